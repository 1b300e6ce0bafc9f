"""List the parameters of a node (like ``ros2 param list``)."""

from __future__ import annotations

import argparse

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, cli_node, node_name, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', type=node_name, help='fully qualified node name, e.g. /classifier')
    parser.add_argument('--param-prefixes', nargs='*', default=[], help='only these prefixes')


def main(args: argparse.Namespace) -> int:
    try:
        with cli_node('param') as node:
            res = call(node, args.node, 'list_parameters',
                       lambda srv: srv.Request(prefixes=args.param_prefixes))
    except CliError as exc:
        return print_error(exc)
    print(f'{args.node}:')
    for name in sorted(res.result.names):
        print(f'  {name}')
    return 0
