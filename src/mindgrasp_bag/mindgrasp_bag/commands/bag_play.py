"""Play a bag (ours, ros2 bag sqlite3/MCAP, rosbags) with its original timing."""

from __future__ import annotations

import argparse
import sys

from mindgrasp_bag.damage import ALLOW_DAMAGED_HELP
from mindgrasp_bag.ros_glue import param_args
from mindgrasp_common.cli_checks import bounded_int, non_negative_float, positive_float


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options in the manner of ``ros2 bag play``."""
    parser.add_argument('bag', help='run directory (runs/<run>), bag directory (holding '
                                    'metadata.yaml), or an .mcap/.db3 file')
    parser.add_argument('-r', '--rate', type=positive_float, default=1.0,
                        help='playback speed factor (default: 1.0, real time)')
    parser.add_argument('-l', '--loop', action='store_true', help='play again from the start')
    parser.add_argument('--start-offset', type=non_negative_float, default=0.0,
                        help='skip this many seconds of the bag beginning')
    parser.add_argument('--topics', nargs='+', default=[], help='play only these topics')
    parser.add_argument('-e', '--regex', default='', help='play only topics matching this regex')
    parser.add_argument('-x', '--exclude-regex', default='',
                        help='do not play topics matching this regex')
    parser.add_argument('--remap', '-m', nargs='+', default=[], metavar='FROM:=TO',
                        help='publish a topic under another name, e.g. /eeg/raw:=/eeg/replayed')
    parser.add_argument('--clock', nargs='?', type=non_negative_float, const=40.0, default=0.0,
                        metavar='HZ',
                        help='publish /clock with the bag time (default 40 Hz when given)')
    parser.add_argument('--priority', type=bounded_int(0, 99), default=0, metavar='1-99',
                        help='real-time (SCHED_FIFO) priority of the playback thread, for timing '
                             'within ~0.1 ms on a loaded machine (needs root or CAP_SYS_NICE)')
    parser.add_argument('--delay', type=non_negative_float, default=0.5,
                        help='wait this many seconds after creating publishers, so subscribers '
                             'match before the first message (default: 0.5)')
    parser.add_argument('--no-progress', action='store_true',
                        help='no progress bar (the summary line is printed at the end)')
    parser.add_argument('--allow-damaged', action='store_true', help=ALLOW_DAMAGED_HELP)


def main(args: argparse.Namespace) -> int:
    """Run the player node in this process until the bag ends (or Ctrl-C)."""
    from mindgrasp_bag import BagError
    from mindgrasp_bag.player import parse_remaps

    try:  # option errors before any ROS set-up
        parse_remaps(args.remap)
        if not args.rate > 0:
            msg = f'--rate must be > 0 (1.0 = real time); {args.rate} is invalid.'
            raise BagError(msg)
    except BagError as exc:
        print(f'mindgrasp bag play: {exc}', file=sys.stderr)
        return 2
    from mindgrasp_bag import player_node

    params = {
        'bag': args.bag, 'rate': float(args.rate), 'loop': bool(args.loop),
        'start_offset': float(args.start_offset), 'topics': list(args.topics) or [''],
        'regex': args.regex, 'exclude_regex': args.exclude_regex,
        'remap': list(args.remap) or [''], 'clock': args.clock > 0,
        'clock_frequency': float(args.clock or 40.0), 'delay': float(args.delay),
        'priority': int(args.priority), 'progress': not args.no_progress,
        'allow_damaged': bool(args.allow_damaged)}
    return player_node.main(['mindgrasp-bag-play', *param_args(params)])
