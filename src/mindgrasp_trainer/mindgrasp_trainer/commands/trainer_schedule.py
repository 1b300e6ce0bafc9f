"""Print the cue schedule of a Graz-BCI session, or the class order of a Trainer session.

    mindgrasp trainer schedule --paradigm graz --n-trials 40 --seed 1            # CSV on stdout
    mindgrasp trainer schedule --paradigm trainer --n-trials 40 --seed 1 --json

The numbers are the ones the nodes will use with the same parameters (same seed, same schedule),
so a session can be planned, checked for balance or documented before it runs.
"""

from __future__ import annotations

import argparse
import collections
import csv
import json
import sys

from mindgrasp_common.cli_checks import (
    OneLineParser,
    bounded_int,
    non_negative_float,
    non_negative_int,
    positive_int,
)
from mindgrasp_trainer.graz import GrazProtocol
from mindgrasp_trainer.protocol import CLASS_NAMES, NO_CLASS, PromptEvent, TrainerError
from mindgrasp_trainer.trainer import TrainerProtocol


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--paradigm', choices=('graz', 'trainer'), default='graz',
                        help='graz: the full phase timeline; trainer: move/wait per trial '
                             '(resets are not known in advance)')  # fmt: skip
    parser.add_argument('--n-trials', type=positive_int, default=40,
                        help='total trials (default 40)')
    parser.add_argument('--classes', type=bounded_int(0, 3), nargs='+', default=[0, 1, 2, 3],
                        help='class indices (0 left hand, 1 right hand, 2 both hands, 3 feet)')
    parser.add_argument('--seed', type=non_negative_int, default=0)
    parser.add_argument('--start-delay', type=non_negative_float, default=5.0,
                        help='s before the first trial')
    parser.add_argument('--max-repeat', type=non_negative_int, default=0,
                        help='graz: longest run of one class, 0 = no limit')  # fmt: skip
    parser.add_argument('--unbalanced', action='store_true',
                        help='trainer: independent draw per trial, as in the paper')
    parser.add_argument('--json', action='store_true', help='one JSON object instead of CSV')


def _trainer_events(proto: TrainerProtocol) -> list[PromptEvent]:
    """The Trainer's timeline when no reset happens."""
    t = proto.start_delay
    events = []
    for trial, k in enumerate(proto.order, start=1):
        events.append(PromptEvent(t, 'move', trial, int(k), proto.move_duration, 'trainer'))
        t += proto.move_duration
        events.append(PromptEvent(t, 'wait', trial, int(k), proto.wait_duration, 'trainer'))
        t += proto.wait_duration
    events.append(PromptEvent(t, 'end', len(proto.order), NO_CLASS, 0.0, 'trainer'))
    return events


def main(args: argparse.Namespace) -> int:
    try:
        if args.paradigm == 'graz':
            events = GrazProtocol(n_trials=args.n_trials, classes=args.classes, seed=args.seed,
                                  start_delay=args.start_delay,
                                  max_repeat=args.max_repeat).schedule()  # fmt: skip
        else:
            proto = TrainerProtocol(n_trials=args.n_trials, classes=args.classes,
                                    seed=args.seed, start_delay=args.start_delay,
                                    balanced=not args.unbalanced)  # fmt: skip
            events = _trainer_events(proto)
    except TrainerError as err:
        print(f'mindgrasp: {err}', file=sys.stderr)
        return 2
    first = {e.trial: e.class_index for e in events if e.class_index != NO_CLASS}
    counts = collections.Counter(CLASS_NAMES[k] for k in first.values())
    if args.json:
        print(json.dumps({
            'paradigm': args.paradigm, 'seed': args.seed, 'n_trials': len(first),
            'class_counts': dict(counts), 'duration_s': round(events[-1].onset, 3),
            'events': [{'onset_s': round(e.onset, 3), 'phase': e.phase, 'trial': e.trial,
                        'class_index': e.class_index, 'class_name': e.class_name,
                        'duration_s': round(e.duration, 3)} for e in events],
        }))  # fmt: skip
        return 0
    w = csv.writer(sys.stdout)
    w.writerow(['onset_s', 'phase', 'trial', 'class_index', 'class_name', 'duration_s'])
    for e in events:
        w.writerow([f'{e.onset:.3f}', e.phase, e.trial, e.class_index, e.class_name,
                    f'{e.duration:.3f}'])  # fmt: skip
    summary = ', '.join(f'{name} {n}' for name, n in sorted(counts.items()))
    print(f'# {len(first)} trials ({summary}), {events[-1].onset:.1f} s', file=sys.stderr)
    return 0


if __name__ == '__main__':
    parser = OneLineParser(prog='mindgrasp trainer schedule', description=__doc__)
    add_arguments(parser)
    sys.exit(main(parser.parse_args()))
