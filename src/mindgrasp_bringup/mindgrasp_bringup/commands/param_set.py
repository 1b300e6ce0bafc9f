"""Set a parameter of a running node (like ``ros2 param set``)."""

from __future__ import annotations

import argparse

import yaml

from mindgrasp_bringup.commands._param_client import call
from mindgrasp_bringup.ros_cli import CliError, cli_node, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', help='fully qualified node name')
    parser.add_argument('name', help='parameter name')
    parser.add_argument('value', help='value as YAML, e.g. 0.5, true, "[C3, C4]"')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.runtime.parameter import Parameter

    try:
        try:
            value = yaml.safe_load(args.value)
            param = Parameter(args.name, value=value)
        except (yaml.YAMLError, TypeError) as exc:
            raise CliError(f'{args.value!r} is not a parameter value: {exc}') from None
        with cli_node('param') as node:
            res = call(node, args.node, 'set_parameters',
                       lambda srv: srv.Request(parameters=[param.to_parameter_msg()]))
    except CliError as exc:
        return print_error(exc)
    result = res.results[0]
    if result.successful:
        print('Set parameter successful')
        return 0
    return print_error(Exception(f'Setting parameter failed: {result.reason}'))
