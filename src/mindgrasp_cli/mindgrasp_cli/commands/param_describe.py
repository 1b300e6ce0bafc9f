"""Describe parameters of a node: type, description, unit, range, read-only (like ``ros2 param
describe``).

    mindgrasp param describe /fsm watchdog_timeout lock_duration
"""

from __future__ import annotations

import argparse

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, cli_node, node_name, print_error

TYPE_NAMES = {0: 'not set', 1: 'boolean', 2: 'integer', 3: 'double', 4: 'string',
              5: 'byte array', 6: 'boolean array', 7: 'integer array', 8: 'double array',
              9: 'string array'}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', type=node_name, help='fully qualified node name, e.g. /fsm')
    parser.add_argument('names', nargs='+', help='parameter names')


def format_descriptor(desc) -> list[str]:
    """The lines ``ros2 param describe`` prints for one ParameterDescriptor."""
    lines = [f'Parameter name: {desc.name}', f'  Type: {TYPE_NAMES.get(desc.type, desc.type)}']
    if desc.description:
        lines.append(f'  Description: {desc.description}')
    constraints = []
    if desc.read_only:
        constraints.append('    Read only: true')
    if desc.dynamic_typing:
        constraints.append('    Dynamic typing: true')
    for rng in list(desc.floating_point_range) + list(desc.integer_range):
        constraints += [f'    Min value: {rng.from_value}', f'    Max value: {rng.to_value}']
        if rng.step:
            constraints.append(f'    Step: {rng.step}')
    if desc.additional_constraints:
        constraints.append(f'    Additional constraints: {desc.additional_constraints}')
    if constraints:
        lines += ['  Constraints:', *constraints]
    return lines


def main(args: argparse.Namespace) -> int:
    try:
        with cli_node('param') as node:
            res = call(node, args.node, 'describe_parameters',
                       lambda srv: srv.Request(names=list(args.names)))
    except CliError as exc:
        return print_error(exc)
    code = 0
    for name, desc in zip(args.names, res.descriptors, strict=False):
        if desc.type == 0:
            print_error(Exception(f'Parameter {name!r} is not declared on {args.node}; list '
                                  f'them with `mindgrasp param list {args.node}`.'))
            code = 1
            continue
        print('\n'.join(format_descriptor(desc)))
    return code
