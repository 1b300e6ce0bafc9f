"""List the topics of the ROS 2 graph (like ``ros2 topic list``)."""

from __future__ import annotations

import argparse

from mindgrasp_cli.ros_cli import cli_node, print_names_and_types, wait_for_graph
from mindgrasp_common.cli_checks import non_negative_float


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('-t', '--show-types', action='store_true', help='also print types')
    parser.add_argument('-c', '--count-topics', action='store_true', help='print the count')
    parser.add_argument('--spin-time', type=non_negative_float, default=1.0,
                        help='seconds of unchanged discovery before answering (default 1)')


def main(args: argparse.Namespace) -> int:
    with cli_node() as node:
        wait_for_graph(node, settle_s=args.spin_time, max_s=args.spin_time + 3)
        topics = node.get_topic_names_and_types()
    print_names_and_types(topics, args.show_types, args.count_topics)
    return 0
