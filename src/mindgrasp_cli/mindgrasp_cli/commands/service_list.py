"""List the services of the ROS 2 graph (like ``ros2 service list``).

    mindgrasp service list -t
"""

from __future__ import annotations

import argparse

from mindgrasp_cli.commands._services import add_graph_arguments, service_names_and_types
from mindgrasp_cli.ros_cli import cli_node, print_names_and_types


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_graph_arguments(parser)
    parser.add_argument('-t', '--show-types', action='store_true',
                        help='additionally show the service type')
    parser.add_argument('-c', '--count-services', action='store_true',
                        help='only display the number of services discovered')


def main(args: argparse.Namespace) -> int:
    with cli_node('service') as node:
        services = service_names_and_types(node, args)
    print_names_and_types(services, args.show_types, args.count_services)
    return 0
