"""Print the publishing rate of a topic (like ``ros2 topic hz``)."""

from __future__ import annotations

import argparse
import time
from collections import deque

import numpy as np

from mindgrasp_cli.ros_cli import (
    CliError,
    cli_node,
    find_topic_type,
    message_type,
    print_error,
    topic_name,
)
from mindgrasp_common.cli_checks import non_negative_float, positive_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('topic', type=topic_name, help='topic name, e.g. /camera/color/image_raw')
    parser.add_argument('-w', '--window', type=positive_int, default=100,
                        help='number of intervals in the statistics window (default 100)')
    parser.add_argument('--duration', type=non_negative_float, default=0.0,
                        help='stop after this many seconds (0: until Ctrl-C)')
    parser.add_argument('--type', type=message_type, help='message type (default: as discovered)')


def stats(stamps: deque) -> tuple[float, float, float, float] | None:
    """(rate Hz, min s, max s, std s) of the arrival intervals, None with < 2 arrivals."""
    if len(stamps) < 2:
        return None
    intervals = np.diff(np.asarray(stamps))
    return 1.0 / intervals.mean(), intervals.min(), intervals.max(), intervals.std()


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros import rclpy

    try:
        with cli_node('hz') as node:
            typename = args.type or find_topic_type(node, args.topic)
            stamps: deque[float] = deque(maxlen=args.window + 1)
            # raw: measuring a rate needs no deserialisation, even of 640x480 images
            node.create_subscription(typename, args.topic, lambda _m: stamps.append(
                time.monotonic()), rclpy.qos.QoSProfile(
                depth=100, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT), raw=True)
            start = next_print = time.monotonic()
            while rclpy.ok():
                rclpy.spin_once(node, timeout_sec=0.05)
                now = time.monotonic()
                if now >= next_print + 1.0:
                    next_print = now
                    result = stats(stamps)
                    if result is None:
                        print('no new messages')
                    else:
                        rate, lo, hi, std = result
                        print(f'average rate: {rate:.3f}\n\tmin: {lo:.3f}s max: {hi:.3f}s '
                              f'std dev: {std:.5f}s window: {len(stamps)}', flush=True)
                if args.duration and now - start >= args.duration:
                    break
    except CliError as exc:
        return print_error(exc)
    return 0
