"""Print a parameter of a node (like ``ros2 param get``)."""

from __future__ import annotations

import argparse

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, cli_node, node_name, print_error

TYPE_LABELS = {1: 'Boolean', 2: 'Integer', 3: 'Double', 4: 'String', 5: 'Byte array',
               6: 'Boolean array', 7: 'Integer array', 8: 'Double array', 9: 'String array'}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', type=node_name, help='fully qualified node name')
    parser.add_argument('name', help='parameter name, e.g. window_length')
    parser.add_argument('--hide-type', action='store_true', help='print the value only')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.runtime.parameter import parameter_value_to_python

    try:
        with cli_node('param') as node:
            res = call(node, args.node, 'get_parameters',
                       lambda srv: srv.Request(names=[args.name]))
    except CliError as exc:
        return print_error(exc)
    value = res.values[0]
    if value.type == 0:
        return print_error(Exception(f"Parameter {args.name!r} is not set on {args.node}."))
    python = parameter_value_to_python(value)
    if args.hide_type:
        print(python)
    else:
        print(f'{TYPE_LABELS[value.type]} value is: {python}')
    return 0
