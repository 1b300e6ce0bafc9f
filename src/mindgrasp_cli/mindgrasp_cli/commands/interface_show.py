"""Print an interface definition with its nested types (like ``ros2 interface show``).

    mindgrasp interface show mindgrasp_msgs/srv/ResetSim
    mindgrasp topic info /bci/prediction | ...  # or pass '-' to read the type from stdin

Types of ROS 2's common_interfaces are shown from their field definitions, without the comments
of their ``.msg`` files (unless ROS 2 is sourced, whose files are then read).
"""

from __future__ import annotations

import argparse
import sys

from mindgrasp_cli.ros_cli import UsageError, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    comments = parser.add_mutually_exclusive_group()
    comments.add_argument('--all-comments', action='store_true',
                          help='show all comments, including those of nested definitions')
    comments.add_argument('--no-comments', action='store_true',
                          help='show no comments or whitespace')
    parser.add_argument('type', help="interface type, e.g. 'mindgrasp_msgs/msg/MIPrediction'; "
                                     "'-' reads it from stdin")


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.interface_text import show
    from mindgrasp_ros.typesupport import MessageTypeError

    typename = sys.stdin.readline().strip() if args.type == '-' else args.type
    try:
        text = show(typename, comments=args.all_comments or not args.no_comments,
                    nested_comments=args.all_comments)
    except MessageTypeError as exc:
        return print_error(UsageError(str(exc)))
    print(text)
    return 0
