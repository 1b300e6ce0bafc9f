"""The services of the graph, shared by ``service list|type`` (ros2service's
``get_service_names_and_types``)."""

from __future__ import annotations

import argparse
from typing import Any

from mindgrasp_cli.ros_cli import is_hidden_name, wait_for_graph
from mindgrasp_common.cli_checks import non_negative_float


def add_graph_arguments(parser: argparse.ArgumentParser) -> None:
    """The options every ``ros2 service`` verb takes."""
    parser.add_argument('--spin-time', type=non_negative_float, default=1.0,
                        help='seconds of unchanged discovery before answering (default 1)')
    parser.add_argument('--include-hidden-services', action='store_true',
                        help='also list hidden services (a name token starting with _)')


def service_names_and_types(node: Any, args: argparse.Namespace) -> list[tuple[str, list[str]]]:
    """``[(name, [type, ...])]`` sorted by name, once discovery has settled (``--spin-time``)."""
    wait_for_graph(node, settle_s=args.spin_time, max_s=args.spin_time + 3)
    return sorted((name, list(types)) for name, types in node.get_service_names_and_types()
                  if args.include_hidden_services or not is_hidden_name(name))
