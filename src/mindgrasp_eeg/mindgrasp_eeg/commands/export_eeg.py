"""Export the EEG of a recorded run (rosbag2) to FIF or EDF, with prompts/targets as annotations.

Examples::

    mindgrasp export eeg runs/20261121T010000_demo                 # -> <run>/eeg_raw.fif
    mindgrasp export eeg runs/20261121T010000_demo/bag --format edf -o session.edf
"""

from __future__ import annotations

import argparse
import sys

from mindgrasp_eeg import EEGError
from mindgrasp_ros.topics import EEG_RAW


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp export eeg``."""
    parser.add_argument('path', metavar='RUN_DIR_OR_BAG', help='run directory or rosbag2 folder')
    parser.add_argument('--format', choices=['fif', 'edf'], default='fif', help='output format')
    parser.add_argument('-o', '--output', default=None,
                        help='output file (default: eeg_raw.fif / eeg.edf in the run directory)')
    parser.add_argument('--eeg-topic', default=EEG_RAW.name, help='topic of the EEGChunk messages')
    parser.add_argument('--overwrite', action='store_true', help='replace an existing file')


def main(args: argparse.Namespace) -> int:
    """Export; 0 on success, 1 with a message on bad input."""
    from mindgrasp_eeg.export import default_output, read_session, write_recording

    try:
        recording = read_session(args.path, args.eeg_topic)   # the bag is read once
        out = write_recording(recording, args.output or default_output(args.path, args.format),
                              args.format, overwrite=args.overwrite)
    except EEGError as exc:
        print(f'mindgrasp export eeg: {exc}', file=sys.stderr)
        return 1
    n_ann = sum(1 for a in recording.annotations if not a[2].startswith('BAD_'))
    print(f'Wrote {out}: {len(recording.data)} samples x {len(recording.channels)} channels at '
          f'{recording.rate:g} Hz ({recording.duration:.1f} s), {n_ann} annotations, '
          f'{recording.n_missing} missing samples.')
    return 0
