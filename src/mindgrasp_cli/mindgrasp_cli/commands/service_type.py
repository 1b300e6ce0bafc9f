"""Print the type of a service (like ``ros2 service type``); exit 1 when no such service is on
the graph (stdout empty as with ros2, and one line on stderr).

    mindgrasp service type /sim/reset
"""

from __future__ import annotations

import argparse

from mindgrasp_cli.commands._services import add_graph_arguments, service_names_and_types
from mindgrasp_cli.ros_cli import CliError, cli_node, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('service_name', help="name of the service, e.g. '/sim/reset'")
    add_graph_arguments(parser)


def main(args: argparse.Namespace) -> int:
    with cli_node('service') as node:
        services = dict(service_names_and_types(node, args))
    if args.service_name not in services:
        return print_error(CliError(
            f"Service '{args.service_name}' is not on the graph; list them with "
            '`mindgrasp service list` and check the ROS_DOMAIN_ID.'))
    for srv_type in services[args.service_name]:
        print(srv_type)
    return 0
