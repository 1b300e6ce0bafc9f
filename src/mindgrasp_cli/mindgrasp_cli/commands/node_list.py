"""List the nodes of the ROS 2 graph (like ``ros2 node list``)."""

from __future__ import annotations

import argparse

from mindgrasp_cli.ros_cli import cli_node, wait_for_graph
from mindgrasp_common.cli_checks import non_negative_float


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('-a', '--all', action='store_true', help='include hidden nodes (_name)')
    parser.add_argument('-c', '--count-nodes', action='store_true', help='print the count')
    parser.add_argument('--spin-time', type=non_negative_float, default=1.0,
                        help='seconds of unchanged discovery before answering (default 1)')


def main(args: argparse.Namespace) -> int:
    with cli_node() as node:
        wait_for_graph(node, settle_s=args.spin_time, max_s=args.spin_time + 3)
        names = node.get_node_names_and_namespaces()
    full = [f'{ns.rstrip("/")}/{name}' for name, ns in names
            if args.all or not name.startswith('_')]
    if args.count_nodes:
        print(len(full))
    else:
        print('\n'.join(sorted(full)))
    return 0
