"""Set a node's parameters from a ROS parameter file (like ``ros2 param load``).

    mindgrasp param load /fsm fsm.yaml

Sets the file's section for the node (``/fsm:`` or ``fsm:``; ``/**`` too with ``--use-wildcard``)
in one ``set_parameters`` call and prints one line per parameter, as ros2 does: ``Set parameter
NAME successful`` on stdout, ``Set parameter NAME failed: REASON`` on stderr (read-only
parameters are refused: restart the node with ``--params-file`` to change them).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, UsageError, cli_node, print_error


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node_name', help='fully qualified node name, e.g. /fsm')
    parser.add_argument('parameter_file', type=Path, help='ROS parameter file (YAML)')
    parser.add_argument('--use-wildcard', action='store_true',
                        help="also load the '/**' section into the node")


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.runtime.arguments import ParamsFileError, load_params_file
    from mindgrasp_ros.runtime.parameter import Parameter

    target = '/' + args.node_name.lstrip('/')
    try:
        try:
            values = load_params_file(args.parameter_file, target,
                                      use_wildcard=args.use_wildcard)
            params = [Parameter(name, value=value) for name, value in values.items()]
        except (ParamsFileError, TypeError) as exc:
            raise UsageError(str(exc)) from None
        if not params:
            msg = (f"{args.parameter_file} has no '{target}: ros__parameters:' section; "
                   f'write one (`mindgrasp param dump {target}` shows the layout).')
            raise UsageError(msg)
        with cli_node('param') as node:
            res = call(node, target, 'set_parameters', lambda srv: srv.Request(
                parameters=[p.to_parameter_msg() for p in params]))
    except CliError as exc:
        return print_error(exc)
    for param, result in zip(params, res.results, strict=True):
        state = 'successful' if result.successful else 'failed'
        reason = f': {result.reason}' if result.reason else ''
        print(f'Set parameter {param.name} {state}{reason}',
              file=sys.stdout if result.successful else sys.stderr)
    return 0
