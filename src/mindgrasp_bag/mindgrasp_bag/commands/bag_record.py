"""Record topics to a rosbag2 bag (MCAP storage, metadata.yaml version 9)."""

from __future__ import annotations

import argparse

from mindgrasp_bag.ros_glue import param_args
from mindgrasp_common.cli_checks import (
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options in the manner of ``ros2 bag record``."""
    parser.add_argument('topics', nargs='*', help='topics to record (default: all)')
    parser.add_argument('-a', '--all', action='store_true',
                        help='record every topic (the default without topics or --regex)')
    parser.add_argument('-e', '--regex', default='', help='record topics matching this regex')
    parser.add_argument('-x', '--exclude-regex', default='',
                        help='do not record topics matching this regex')
    parser.add_argument('-o', '--output', default='',
                        help='bag directory to create (default: rosbag2_<date>-<time>)')
    parser.add_argument('-b', '--max-bag-size', type=non_negative_int, default=0,
                        help='start a new .mcap file at this size in bytes (0: never)')
    parser.add_argument('-d', '--max-bag-duration', type=non_negative_float, default=0.0,
                        help='start a new .mcap file after this many seconds (0: never)')
    parser.add_argument('--compression', choices=('none', 'zstd', 'lz4'), default='none',
                        help='MCAP chunk compression (default: none)')
    parser.add_argument('--flush-interval', type=positive_float, default=1.0,
                        help='longest time in s before written messages reach the file, which '
                             'bounds the loss if the recorder is killed (default: 1.0)')
    parser.add_argument('--max-queue-mb', type=positive_int, default=512,
                        help='memory for messages waiting for the disk, MiB (default: 512)')
    parser.add_argument('--duration', type=non_negative_float, default=0.0,
                        help='stop after this many seconds (default: until Ctrl-C)')


def main(args: argparse.Namespace) -> int:
    """Run the recorder node in this process until Ctrl-C or ``--duration``."""
    from mindgrasp_bag import recorder_node

    params = {
        'output': args.output, 'topics': list(args.topics) or [''], 'regex': args.regex,
        'exclude_regex': args.exclude_regex, 'max_bag_size': int(args.max_bag_size),
        'max_bag_duration': float(args.max_bag_duration), 'compression': args.compression,
        'flush_interval': float(args.flush_interval), 'max_queue_mb': int(args.max_queue_mb),
        'duration': float(args.duration)}
    return recorder_node.main(['mindgrasp-bag-record', *param_args(params)])

