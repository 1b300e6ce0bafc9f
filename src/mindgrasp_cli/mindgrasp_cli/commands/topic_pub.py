"""Publish a message given as YAML (like ``ros2 topic pub``)."""

from __future__ import annotations

import argparse
import time

import yaml

from mindgrasp_cli.ros_cli import (
    CliError,
    UsageError,
    cli_node,
    message_type,
    print_error,
    set_fields,
    topic_name,
)
from mindgrasp_common.cli_checks import non_negative_int, positive_float, yaml_error_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('topic', type=topic_name, help='topic name, e.g. /arm_controller/commands')
    parser.add_argument('type', type=message_type,
                        help='message type, e.g. std_msgs/msg/Float64MultiArray')
    parser.add_argument('values', nargs='?', default='{}',
                        help='YAML of the fields, e.g. "{data: [0.1, 0, 0, 0, 0, 0]}"')
    parser.add_argument('-r', '--rate', type=positive_float, default=1.0, help='Hz (default 1)')
    parser.add_argument('-1', '--once', action='store_true', help='publish once and exit')
    parser.add_argument('-t', '--times', type=non_negative_int, default=0,
                        help='publish N times and exit')
    parser.add_argument('-w', '--wait-matching-subscriptions', type=non_negative_int, default=1,
                        help='wait for this many subscribers before publishing (default 1)')
    parser.add_argument('--qos-durability', choices=['volatile', 'transient_local'],
                        default='volatile')
    parser.add_argument('--qos-reliability', choices=['reliable', 'best_effort'],
                        default='reliable')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros import rclpy
    from mindgrasp_ros.typesupport import MessageTypeError, get_message_class

    try:
        try:
            cls = get_message_class(args.type)
        except MessageTypeError as exc:
            raise CliError(str(exc)) from None
        try:
            values = yaml.safe_load(args.values) or {}
        except yaml.YAMLError as exc:
            raise UsageError(f'The values are not valid YAML ({yaml_error_text(exc)}); write '
                             'them as a mapping, e.g. "{data: 1.0}".') from None
        if not isinstance(values, dict):
            raise UsageError('The values must be a YAML mapping, e.g. "{data: 1.0}".')
        msg = set_fields(cls(), values)
        qos = rclpy.qos.QoSProfile(
            depth=10,
            reliability=rclpy.qos.ReliabilityPolicy[args.qos_reliability.upper()],
            durability=rclpy.qos.DurabilityPolicy[args.qos_durability.upper()])
        times = 1 if args.once else args.times
        with cli_node('pub') as node:
            pub = node.create_publisher(cls, args.topic, qos)
            deadline = time.monotonic() + 5.0
            while (pub.get_subscription_count() < args.wait_matching_subscriptions
                   and time.monotonic() < deadline):
                time.sleep(0.05)
            count = 0
            while rclpy.ok():
                pub.publish(msg)
                count += 1
                print(f'publishing #{count}: {msg}', flush=True)
                if times and count >= times:
                    break
                time.sleep(1.0 / args.rate)
            pub.wait_for_all_acked(rclpy.duration.Duration(seconds=2))
    except CliError as exc:
        return print_error(exc)
    return 0
