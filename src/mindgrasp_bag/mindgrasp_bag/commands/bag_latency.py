"""Print a live run's latencies (EEG sample -> /eeg/raw -> /bci/prediction -> arm command, per hop
and end to end, p50/p95/p99 with counts), the display's cue-to-flip delay and the jitter of its
periodic topics, from the recorded stamps."""

from __future__ import annotations

import argparse
import json
import sys

from mindgrasp_bag import BagError
from mindgrasp_bag.latency import LatencyError, format_report, latency_report
from mindgrasp_bag.paths import resolve_bag
from mindgrasp_bag.run_stamps import read_run_stamps


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag latency <run> [--json]``."""
    parser.add_argument('run', help='run directory (runs/<run>), its bag folder, or an .mcap file')
    parser.add_argument('--json', action='store_true',
                        help='print the report as one JSON object on the last line (end_to_end, '
                             'hops, cue_to_flip, jitter; milliseconds)')


def main(args: argparse.Namespace) -> int:
    """Print the report; 1 with one line saying why when the run cannot give latencies."""
    try:
        report = latency_report(read_run_stamps(resolve_bag(args.run)))
    except (BagError, LatencyError, OSError) as exc:
        print(f'mindgrasp bag latency: {exc}', file=sys.stderr)
        return 1
    if args.json:
        print(json.dumps(report))
    else:
        print(format_report(report))
    return 0
