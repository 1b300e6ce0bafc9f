"""Repair a crashed recording (as ``ros2 bag reindex``): finish its .mcap files, rebuild metadata.

    mindgrasp bag reindex runs/<run>          # or runs/<run>/bag

Each unfinished or damaged .mcap file is rewritten with every readable record and a summary, so
the plain mcap reader and every rosbag2 tool (ros2 bag, rosbags, Foxglove) open it; then
metadata.yaml is rebuilt from the files.
"""

from __future__ import annotations

import argparse
import sys


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag reindex <bag>``."""
    parser.add_argument('bag', help='run directory (runs/<run>) or bag directory')


def main(args: argparse.Namespace) -> int:
    """Reindex; 2 when the path does not exist, 1 when it is not an MCAP bag."""
    from mindgrasp_bag import BagError
    from mindgrasp_bag.integrity import reindex, verify_bag
    from mindgrasp_bag.paths import resolve_bag

    try:
        bag = resolve_bag(args.bag)
    except BagError as exc:     # a missing path is a usage error, as in `ros2 bag` (exit 2)
        print(f'mindgrasp bag reindex: {exc}', file=sys.stderr)
        return 2
    try:
        done = reindex(bag)
        left = verify_bag(bag)
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag reindex: {exc}', file=sys.stderr)
        return 1
    for line in done:
        print(line)
    for line in left:
        print(f'Still damaged: {line}', file=sys.stderr)
    return 1 if left else 0
