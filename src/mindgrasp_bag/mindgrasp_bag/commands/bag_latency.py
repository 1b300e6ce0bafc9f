"""Print a live run's latencies (EEG sample -> /eeg/raw -> /bci/prediction -> arm command, per hop
and end to end, p50/p95/p99 with counts), the display's cue-to-flip delay and the jitter of its
periodic topics, from the recorded stamps.

A damaged or unfinished bag (a recorder killed, a disk full, damaged chunks) is read as far as it
can be, as by every bag tool: the report covers the readable messages, each damage is printed
with its file and byte offset, and the exit code is 1 unless ``--allow-damaged``."""

from __future__ import annotations

import argparse
import json
import sys

from mindgrasp_bag import BagError
from mindgrasp_bag.damage import ALLOW_DAMAGED_HELP, assess_bag
from mindgrasp_bag.latency import LatencyError, format_report, latency_report
from mindgrasp_bag.paths import resolve_bag
from mindgrasp_bag.run_stamps import read_run_stamps


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag latency <run> [--json]``."""
    parser.add_argument('run', help='run directory (runs/<run>), its bag folder, or an .mcap file')
    parser.add_argument('--json', action='store_true',
                        help='print the report as one JSON object on the last line (end_to_end, '
                             'hops, cue_to_flip, jitter; milliseconds)')
    parser.add_argument('--allow-damaged', action='store_true', help=ALLOW_DAMAGED_HELP)


def main(args: argparse.Namespace) -> int:
    """Print the report; 1 with one line saying why when the run cannot give latencies, and 1
    on a damaged bag unless ``--allow-damaged`` (the report of its readable part is printed)."""
    try:
        bag = resolve_bag(args.run)
        damage = assess_bag(bag)
        lines = damage.lines()
        report = latency_report(read_run_stamps(bag))
    except (BagError, LatencyError, OSError) as exc:
        print(f'mindgrasp bag latency: {exc}', file=sys.stderr)
        return 1
    if lines:
        report['damage'] = damage.as_dict()
    if args.json:
        print(json.dumps(report))
    else:
        print(format_report(report))
    for line in lines:
        print(f'mindgrasp bag latency: {line}', file=sys.stderr)
    if lines and not args.allow_damaged:
        print('mindgrasp bag latency: the bag is damaged; the figures are from its readable part '
              '(pass --allow-damaged to accept it).', file=sys.stderr)
        return 1
    return 0
