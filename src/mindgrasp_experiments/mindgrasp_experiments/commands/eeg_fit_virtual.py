"""Fit the virtual subject's decodability to a replay subject's real EEG (separability, ...).

Measures the real subject's decodability figures (4 classes, left vs right, hands vs feet, rest
vs any imagery, rest vs both hands: calibrated on its calibration recordings, tested on its play
recordings, :mod:`mindgrasp_experiments.decodability`), then searches the virtual subject's
``separability``, ``lateral_separability``, ``rest_separability`` and ``nonstationarity`` so that
synthetic sessions on the same cue schedules give the same figures. Prints real vs fitted per
figure; ``--output`` writes the values as a ROS parameter file for the virtual amplifier.

Examples::

    mindgrasp eeg fit-virtual --subject eegmmidb:1
    mindgrasp eeg fit-virtual --subject eegmmidb:1 --seed 3 --output virtual_s001.yaml
    mindgrasp eeg fit-virtual --subject docs/subjects/eegmmidb_s001.yaml --json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from mindgrasp_common.cli_checks import non_negative_int, positive_int
from mindgrasp_eeg import EEGError

if TYPE_CHECKING:
    from mindgrasp_experiments.decodability import Decodability, FitResult

PROG = 'mindgrasp eeg fit-virtual'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp eeg fit-virtual``."""
    parser.add_argument('--subject', required=True,
                        help='replay subject: eegmmidb:<n> or a subject file (.yaml)')
    parser.add_argument('--seed', type=non_negative_int, default=0,
                        help='seed of the virtual sessions (the same seed, the same fit)')
    parser.add_argument('--head-seed', type=non_negative_int, default=0,
                        help="the virtual subject's head model (virtual_amp head_seed)")
    parser.add_argument('--repeats', type=positive_int, default=24,
                        help='virtual sessions averaged per setting (more: less noise, slower)')
    parser.add_argument('--iterations', type=positive_int, default=2,
                        help='Gauss-Newton iterations (each measures 7 settings at most)')
    parser.add_argument('--jobs', type=positive_int, default=None,
                        help='parallel processes (default: the usable CPUs, at most 4)')
    parser.add_argument('--output', metavar='FILE',
                        help='write the fitted values as a ROS parameter file (virtual_amp)')
    parser.add_argument('--json', action='store_true',
                        help='print the result as JSON instead of the table')


def format_table(result: FitResult, subject: str) -> str:
    """Real vs fitted virtual figures, one line per figure, then the fitted values."""
    from mindgrasp_experiments.decodability import FIGURES

    real, syn, check = result.real, result.synthetic, result.check
    lines = [f'Decodability: {subject} (real) vs the fitted virtual subject',
             'balanced accuracy on the test set, mean of MDM and TS+LR (each in brackets); '
             '+- = sampling error of the real figure',
             '',
             f'{"figure":<24} {"chance":>6}  {"real":>24}  {"virtual (fit)":>17}  {"diff":>5}'
             + (f'  {"fresh":>5}  {"diff":>5}' if check is not None else '')]

    def cell(d: Decodability, name: str) -> str:
        parts = '/'.join(f'{v:.2f}' for v in d.accuracy[name].values())
        return f'{d.score(name):.2f} ({parts})'

    def diff(d: Decodability, name: str) -> str:
        r, s = real.score(name), d.score(name)
        return f'{s - r:+.2f}' if math.isfinite(r) and math.isfinite(s) else 'n/a'

    for fig in FIGURES:
        name = fig.name
        line = (f'{fig.title:<24} {fig.chance:>6.2f}  '
                f'{cell(real, name) + f" +-{real.standard_error(name):.2f}":>24}  '
                f'{cell(syn, name):>17}  {diff(syn, name):>5}')
        if check is not None:
            line += f'  {check.score(name):>5.2f}  {diff(check, name):>5}'
        lines.append(line)
    params = ', '.join(f'{k} {v:g}' for k, v in result.params.items())
    lines += ['', f'fitted: {params}',
              f'RMS difference {result.error:.3f}, largest {result.max_error:.3f} '
              f'({result.n_evaluations} settings x {syn.repeats} virtual sessions)']
    if check is not None:
        doc = result.to_dict()
        lines.append(f'fresh sessions (other seeds): RMS difference {doc["check_error"]:.3f}, '
                     f'largest {doc["check_max_error"]:.3f}')
    return '\n'.join(lines)


def parameter_file(params: dict[str, float], subject: str, command: str, error: float,
                   head_seed: int = 0) -> str:
    """The fitted values as a ROS 2 parameter file for the virtual participant's node (with the
    head they were fitted for)."""
    from mindgrasp_experiments.fitted_subject import virtual_subject_node

    body = '\n'.join(f'    {k}: {v:g}' for k, v in {'head_seed': head_seed, **params}.items())
    return (f'# Virtual subject fitted to {subject}: `{command}`\n'
            '# (decodability figures of mindgrasp_experiments.decodability within '
            f'{error:.3f} RMS of '
            'the real ones).\n'
            f'{virtual_subject_node()}:\n  ros__parameters:\n{body}\n')


def main(args: argparse.Namespace) -> int:
    """Run the fit; 0, or 2 with one line on a bad subject or setting."""
    from mindgrasp_experiments.decodability import (
        RunSchedule,
        common_channels,
        default_jobs,
        fit_virtual,
        measure,
        replay_recordings,
    )

    started = time.monotonic()
    try:
        cal, test, source = replay_recordings(args.subject)
        channels = common_channels(cal[0].channels)
        real = measure(cal, test, channels=channels, source=source)
    except EEGError as exc:
        print(f'{PROG}: {exc}', file=sys.stderr)
        return 2
    from tqdm import tqdm

    n_max = 2 + 7 * args.iterations
    bar = tqdm(total=n_max, desc='fit-virtual', unit='setting', file=sys.stderr,
               disable=None, leave=False)

    def progress(n: int) -> None:
        bar.update(n - bar.n)

    try:
        result = fit_virtual(real, [RunSchedule.of(r) for r in cal],
                             [RunSchedule.of(r) for r in test], channels=channels,
                             seed=args.seed, repeats=args.repeats,
                             iterations=args.iterations, head_seed=args.head_seed,
                             jobs=args.jobs or default_jobs(), progress=progress)
    except EEGError as exc:
        bar.close()
        print(f'{PROG}: {exc}', file=sys.stderr)
        return 2
    bar.close()
    elapsed = time.monotonic() - started
    command = (f'{PROG} --subject {args.subject} --seed {args.seed} --head-seed '
               f'{args.head_seed} --repeats {args.repeats} --iterations {args.iterations}')
    if args.output:
        out = Path(args.output)
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(parameter_file(result.params, source, command, result.error,
                                          args.head_seed))
        except OSError as exc:
            print(f'{PROG}: cannot write {out} ({exc.strerror}); choose a writable path.',
                  file=sys.stderr)
            return 2
    if args.json:
        doc = {'subject': source, 'seed': args.seed, 'head_seed': args.head_seed,
               'channels': channels, 'elapsed_s': round(elapsed, 1), **result.to_dict()}
        print(json.dumps(doc, indent=2))
    else:
        print(format_table(result, source))
        print(f'{elapsed:.0f} s' + (f'; parameters written to {args.output}' if args.output
                                    else ''))
    return 0
