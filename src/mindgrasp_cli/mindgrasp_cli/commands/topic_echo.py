"""Print messages of a topic as YAML (like ``ros2 topic echo``)."""

from __future__ import annotations

import argparse
import time

from mindgrasp_cli.ros_cli import (
    CliError,
    cli_node,
    find_topic_type,
    message_to_yaml,
    message_type,
    print_error,
    resolve_field,
    topic_name,
)
from mindgrasp_common.cli_checks import non_negative_float, non_negative_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('topic', type=topic_name, help='topic name, e.g. /joint_states')
    parser.add_argument('type', nargs='?', type=message_type,
                        help='message type (default: as discovered)')
    parser.add_argument('--once', action='store_true', help='print one message and exit')
    parser.add_argument('--times', type=non_negative_int, default=0, help='exit after N messages')
    parser.add_argument('--field', help='print only this field, e.g. header.stamp')
    parser.add_argument('--truncate-length', type=non_negative_int, default=128,
                        help='longest array/string printed in full (0: no limit; default 128)')
    parser.add_argument('--qos-reliability', choices=['reliable', 'best_effort'],
                        default='best_effort', help='best_effort (default) matches any writer')
    parser.add_argument('--timeout', type=non_negative_float, default=0.0,
                        help='give up after this many seconds without a message (0: never)')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros import rclpy

    try:
        with cli_node('echo') as node:
            typename = args.type or find_topic_type(node, args.topic)
            qos = rclpy.qos.QoSProfile(
                depth=10, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT
                if args.qos_reliability == 'best_effort'
                else rclpy.qos.ReliabilityPolicy.RELIABLE)
            limit = 1 if args.once else args.times
            count = [0]
            truncate = args.truncate_length or None

            def show(msg: object) -> None:
                if limit and count[0] >= limit:
                    return
                value = resolve_field(msg, args.field) if args.field else msg
                print(message_to_yaml(value, truncate) + '---', flush=True)
                count[0] += 1

            node.create_subscription(typename, args.topic, show, qos)
            last = time.monotonic()
            while rclpy.ok() and not (limit and count[0] >= limit):
                before = count[0]
                rclpy.spin_once(node, timeout_sec=0.1)
                if count[0] != before:
                    last = time.monotonic()
                elif args.timeout and time.monotonic() - last > args.timeout:
                    raise CliError(f"No message on '{args.topic}' for {args.timeout:.0f} s.")
    except CliError as exc:
        return print_error(exc)
    return 0
