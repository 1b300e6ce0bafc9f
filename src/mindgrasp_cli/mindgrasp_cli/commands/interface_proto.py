"""Print a message (or a service request) with default values as YAML, quoted, ready to paste
into ``topic pub`` or ``service call`` (like ``ros2 interface proto``).

    mindgrasp interface proto mindgrasp_msgs/srv/ResetSim
"""

from __future__ import annotations

import argparse

from mindgrasp_cli.ros_cli import UsageError, message_to_yaml, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('type', help="interface type, e.g. 'geometry_msgs/msg/Point'")
    parser.add_argument('--no-quotes', action='store_true', help='print without outer quotes')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.interface_text import show
    from mindgrasp_ros.typesupport import MessageTypeError, get_message_class, get_service_class

    try:
        show(args.type)   # checks the name, with the known types in the message
        if args.type.split('/')[1] == 'srv':
            instance = get_service_class(args.type).Request()
        else:
            instance = get_message_class(args.type)()
    except MessageTypeError as exc:
        return print_error(UsageError(str(exc)))
    text = message_to_yaml(instance, truncate=None)
    print(text if args.no_quotes else f'"{text}"')
    return 0
