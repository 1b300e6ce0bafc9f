"""Rebuild the summary, report and plots of an experiment run directory from its records.

    mindgrasp experiment report runs/2026-11-22T18-00-00Z_set_locations
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment report``."""
    parser.add_argument('run_dir', help='run directory of mindgrasp experiment')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_experiments.report import rebuild

    run_dir = Path(args.run_dir)
    if not run_dir.is_dir():
        print(f'mindgrasp experiment report: {run_dir} is not a directory; give the run '
              'directory of an experiment.', file=sys.stderr)
        return 2
    try:
        doc = rebuild(run_dir)
    except FileNotFoundError as exc:
        print(f'mindgrasp experiment report: {exc}', file=sys.stderr)
        return 2
    except OSError as exc:      # a full or read-only disk: the records are untouched
        print(f'mindgrasp experiment report: cannot write the report into {run_dir} '
              f'({exc.strerror or exc}); the records are unchanged. Free space, or copy the '
              'run directory to a writable disk and run the command there.', file=sys.stderr)
        return 1
    s = doc['summary']
    cut = f" (and {s['interrupted_trials']} interrupted)" if s['interrupted_trials'] else ''
    print(f"{s['trials']} trials{cut}: report {run_dir / 'report.md'}")
    return 0
