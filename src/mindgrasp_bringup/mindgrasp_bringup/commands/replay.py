"""Replay a recorded run: re-run the classifier (and the controller) on its recorded inputs and
compare with what they decided live.

    mindgrasp replay runs/<run>                       # classifier, same model and parameters
    mindgrasp replay runs/<run> --controller          # the controller too (open loop)
    mindgrasp replay runs/<run> --model my.json --min-agreement 0.9 --json

The nodes run lock-step on the bag's clock (every recorded input at its recorded time), so with
the same model and parameters the predictions agree 100 %. The report (report.md, comparison.json,
predictions.csv, states.csv, timeline.png, replayed_bag/) goes to <run>/replays/<time>/.
"""

from __future__ import annotations

import argparse
import json
import sys

import yaml

from mindgrasp_bag.damage import ALLOW_DAMAGED_HELP
from mindgrasp_common.cli_checks import probability


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp replay RUN [--controller] [--model M] [-p node.name:=value] ...``."""
    parser.add_argument('run', help='run directory (runs/<run>) or its bag folder')
    parser.add_argument('--controller', action='store_true',
                        help='re-run the controller too (open loop: the camera and joint states '
                             'are the recorded ones)')
    parser.add_argument('--model', default='',
                        help='classifier model (.json); default: the one the run used')
    parser.add_argument('-p', '--param', action='append', default=[], metavar='NODE.NAME:=VALUE',
                        help='override a parameter of a re-run node, e.g. '
                             'classifier.min_certainty:=0.6 (YAML value)')
    parser.add_argument('-o', '--output', default=None,
                        help='report directory (default: <run>/replays/<UTC time>)')
    parser.add_argument('--min-agreement', type=probability, default=0.0, metavar='0-1',
                        help='exit 1 when the prediction agreement is below this (a regression '
                             'check after changing code)')
    parser.add_argument('--json', action='store_true',
                        help='print the comparison as one JSON object on the last line')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')
    parser.add_argument('--allow-damaged', action='store_true', help=ALLOW_DAMAGED_HELP)


def parse_params(items: list[str]) -> dict[str, dict[str, object]]:
    """``['classifier.min_certainty:=0.6']`` -> ``{'classifier': {'min_certainty': 0.6}}``."""
    from mindgrasp_bag import BagError
    from mindgrasp_bringup.replay.engine import NODES

    out: dict[str, dict[str, object]] = {}
    for item in items:
        name, sep, value = item.partition(':=')
        node, dot, param = name.partition('.')
        if not sep or not dot or node not in NODES or not param:
            msg = (f'-p {item!r} is not NODE.NAME:=VALUE with NODE one of {", ".join(NODES)}; '
                   'e.g. -p classifier.min_certainty:=0.6.')
            raise BagError(msg)
        out.setdefault(node, {})[param] = yaml.safe_load(value) if value else ''
    return out


def main(args: argparse.Namespace) -> int:
    """Replay, write the report, print the summary line; 2 on bad arguments."""
    from mindgrasp_bag import BagError
    from mindgrasp_bringup.replay import ReplayConfig, damage_lines, run_replay, summary_line

    try:
        if not 0.0 <= args.min_agreement <= 1.0:
            msg = f'--min-agreement must be between 0 and 1; {args.min_agreement} is invalid.'
            raise BagError(msg)
        params = parse_params(args.param)
    except BagError as exc:
        print(f'mindgrasp replay: {exc}', file=sys.stderr)
        return 2
    cfg = ReplayConfig(args.run, controller=args.controller, model=args.model, params=params,
                       output=args.output, progress=not args.no_progress)
    try:
        result = run_replay(cfg)
    except BagError as exc:
        print(f'mindgrasp replay: {exc}', file=sys.stderr)
        return 2
    except OSError as exc:      # the report cannot be written (full disk, read-only run)
        print(f'mindgrasp replay: cannot write the report to {exc.filename or cfg.output} '
              f'({exc.strerror or exc}); pass -o DIR on a disk with space.', file=sys.stderr)
        return 1
    print(summary_line(result), flush=True)
    if args.json:
        print(json.dumps(result.summary), flush=True)
    lines = damage_lines(result, args.allow_damaged)
    for line in lines:
        print(f'mindgrasp replay: {line}', file=sys.stderr)
    code = 1 if lines and not args.allow_damaged else 0
    agreement = result.summary['prediction_agreement'] or 0.0
    if agreement < args.min_agreement:
        print(f'mindgrasp replay: prediction agreement {agreement:.3f} is below '
              f'--min-agreement {args.min_agreement:.3f}.', file=sys.stderr)
        code = 1
    return code
