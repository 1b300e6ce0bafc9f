"""Print every parameter of a node as a ROS parameter file (like ``ros2 param dump``).

    mindgrasp param dump /fsm > fsm.yaml
    mindgrasp param dump /fsm --output-dir params/     # writes params/fsm.yaml

The file is what ``--params-file`` and ``mindgrasp param load`` read: ``/fsm: ros__parameters:``
with dotted names nested (``colour_ranges.red`` under ``colour_ranges:``).
"""

from __future__ import annotations

import argparse
from typing import Any

import yaml

from mindgrasp_cli.commands._param_client import call
from mindgrasp_cli.ros_cli import CliError, cli_node, print_error
from mindgrasp_common.cli_checks import existing_directory


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node_name', help='fully qualified node name, e.g. /fsm')
    parser.add_argument('--output-dir', type=existing_directory,
                        help='write <node>.yaml there instead of printing it (as ros2 Humble)')


def node_parameters(node: Any, target: str) -> dict[str, Any]:
    """``{name: python value}`` of every parameter of ``target``, sorted by name."""
    from mindgrasp_ros.runtime.parameter import parameter_value_to_python

    names = sorted(call(node, target, 'list_parameters',
                        lambda srv: srv.Request()).result.names)
    values = call(node, target, 'get_parameters', lambda srv: srv.Request(names=names)).values
    return {name: parameter_value_to_python(v) for name, v in zip(names, values, strict=True)}


def parameter_file(target: str, params: dict[str, Any]) -> str:
    """YAML of a ROS parameter file: ``{target: {ros__parameters: nested}}``."""
    nested: dict[str, Any] = {}
    for name, value in params.items():
        *heads, last = name.split('.')
        level = nested
        for head in heads:
            level = level.setdefault(head, {})
        level[last] = value
    return yaml.safe_dump({target: {'ros__parameters': nested}}, default_flow_style=False)


def main(args: argparse.Namespace) -> int:
    target = '/' + args.node_name.lstrip('/')
    try:
        with cli_node('param') as node:
            text = parameter_file(target, node_parameters(node, target))
    except CliError as exc:
        return print_error(exc)
    if args.output_dir is None:
        print(text)
        return 0
    path = args.output_dir / (target.lstrip('/').replace('/', '__') + '.yaml')
    path.write_text(text, encoding='utf-8')
    print(f'Saving to:  {path}')
    return 0
