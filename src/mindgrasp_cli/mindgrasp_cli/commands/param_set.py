"""Set a parameter of a running node (like ``ros2 param set``)."""

from __future__ import annotations

import argparse

import yaml

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, UsageError, cli_node, node_name, print_error
from mindgrasp_common.cli_checks import yaml_error_text


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', type=node_name, help='fully qualified node name')
    parser.add_argument('name', help='parameter name')
    parser.add_argument('value', help='value as YAML, e.g. 0.5, true, "[C3, C4]"')


def _check_range(name: str, param: object) -> None:
    """Integers of a parameter are int64 on the wire: refuse what does not fit, naming the
    parameter and the range (``99999999999999999999`` ended in ``struct.error``)."""
    from mindgrasp_ros.value_ranges import check_value

    what = f'parameter {name!r}'
    kind = param.type_.name
    if kind == 'INTEGER':
        check_value(what, 'int64', param.value)
    elif kind == 'INTEGER_ARRAY':
        check_value(what, 'sequence<int64>', list(param.value))


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.runtime.parameter import Parameter

    try:
        try:
            value = yaml.safe_load(args.value)
        except yaml.YAMLError as exc:
            msg = (f'{args.value!r} is not a parameter value ({yaml_error_text(exc)}); write it '
                   'as YAML, e.g. 0.5, true, "[C3, C4]".')
            raise UsageError(msg) from None
        try:
            param = Parameter(args.name, value=value)
            _check_range(args.name, param)
        except (TypeError, ValueError) as exc:
            raise UsageError(f'{args.value!r} is not a parameter value: {exc}') from None
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
