"""Start a launch profile or a *.launch.py file: every node, the recorder and a run directory."""

from __future__ import annotations

import argparse
import ast
import shlex
import sys

from mindgrasp_common.cli_checks import (
    OneLineParser,
    bounded_float,
    non_negative_float,
    positive_float,
)
from mindgrasp_launch import LaunchError, LaunchService, profiles
from mindgrasp_launch.description import LAUNCH_SUFFIX, PROFILE_DIR
from mindgrasp_launch.service import format_arguments

EPILOG = """examples:
  mindgrasp launch demo                      headless demo, recorded to runs/<UTC time>_demo/
  mindgrasp launch demo gui:=true duration:=120
  mindgrasp launch hardware eeg_stream:=MyAmp arm_driver:=my_arm_driver
  mindgrasp launch demo --show-args          the arguments of a profile
  mindgrasp launch my_setup.launch.py record:=false
  mindgrasp launch experiment subject:=oracle trials:=2 --lockstep
"""


def _options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--composed', action='store_true',
                        help='run the node modules in one process (mindgrasp_ros.graph)')
    parser.add_argument('--lockstep', action='store_true',
                        help='compose the nodes in one process on simulated time, stepped as '
                             'fast as the CPU allows (deterministic for a seed; LSL nodes are '
                             'left out, the virtual amplifier publishes /eeg/raw itself)')
    parser.add_argument('--run-dir', metavar='DIR',
                        help='run directory (default: runs/<UTC timestamp>_<profile>/)')
    parser.add_argument('--duration', type=non_negative_float, metavar='S',
                        help='end the launch after S seconds (same as duration:=S)')
    parser.add_argument('-s', '--show-args', action='store_true',
                        help='print the launch arguments of the profile and exit')
    parser.add_argument('--dry-run', action='store_true',
                        help='print the processes and their command lines, start nothing')
    parser.add_argument('--list', action='store_true', help='list the profiles and exit')
    parser.add_argument('--sigint-timeout', type=positive_float, default=10.0, metavar='S',
                        help='seconds a node gets to stop after SIGINT before SIGTERM '
                             '(default 10: Python nodes may take seconds to leave DDS on a '
                             'loaded machine)')
    parser.add_argument('--sigterm-timeout', type=positive_float, default=5.0, metavar='S',
                        help='seconds after SIGTERM before SIGKILL (default 5)')
    parser.add_argument('--graph-check', type=bounded_float(0.0, 60.0), default=1.0,
                        metavar='S',
                        help='seconds to look for another graph (a /sim or /fsm node) on the '
                             'ROS domain before anything starts; one is refused in one line '
                             'naming the domain to change (default 1; 0: not looked for)')


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp launch``; launch arguments and options may come in any order."""
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = EPILOG
    parser.add_argument('profile', nargs='?',
                        help='a profile (' + ', '.join(profiles()) + ') or a *.launch.py path')
    _options(parser)
    parser.add_argument('launch_arguments', nargs=argparse.REMAINDER, metavar='name:=value',
                        help='launch arguments (see --show-args)')


def _split_remainder(args: argparse.Namespace) -> argparse.Namespace:
    """Options written after the first name:=value are parsed here (argparse stops there)."""
    given, options = [], []
    for item in args.launch_arguments:
        (options if item.startswith('-') or (options and options[-1] in _TAKES_VALUE
                                             and ':=' not in item) else given).append(item)
    if options:
        parser = OneLineParser(prog='mindgrasp launch')
        _options(parser)
        parser.parse_args(options, namespace=args)  # keeps what is set, adds the rest
    args.launch_arguments = given
    return args


_TAKES_VALUE = ('--run-dir', '--duration', '--sigint-timeout', '--sigterm-timeout',
                '--graph-check')


def profile_summaries() -> list[tuple[str, str]]:
    """``(profile, first docstring line)`` of every profile, without importing them."""
    out = []
    for name in profiles():
        path = PROFILE_DIR / f'{name}{LAUNCH_SUFFIX}'
        try:
            doc = ast.get_docstring(ast.parse(path.read_text(encoding='utf-8'))) or ''
        except (OSError, SyntaxError):
            doc = ''
        paragraph = ' '.join(doc.strip().split('\n\n')[0].split())
        if len(paragraph) > 86:
            paragraph = paragraph[:85].rsplit(' ', 1)[0] + ' ...'
        out.append((name, paragraph))
    return out


def main(args: argparse.Namespace) -> int:
    """Run ``mindgrasp launch``; 0 when every node ended cleanly, 1 on a failure, 2 on bad
    input."""
    args = _split_remainder(args)
    if args.list or args.profile is None:
        print('profiles (mindgrasp launch <profile> [name:=value ...]):')
        for name, doc in profile_summaries():
            print(f'  {name:<10} {doc}')
        return 0 if args.list else 2
    launch_arguments = list(args.launch_arguments)
    if args.duration is not None:
        launch_arguments.append(f'duration:={args.duration:g}')
    try:
        service = LaunchService(args.profile, launch_arguments, run_dir=args.run_dir,
                                composed=args.composed, sigint_timeout=args.sigint_timeout,
                                sigterm_timeout=args.sigterm_timeout,
                                graph_check=args.graph_check,
                                argv=['mindgrasp', 'launch', *sys.argv[2:]])
        if args.show_args:
            print(format_arguments(service.declared_arguments()))
            return 0
        if args.dry_run:
            plan = service.plan(strict=False)
            print(f"launch '{plan.name}' ({plan.launch_file}), arguments:")
            for name, value in plan.arguments.items():
                print(f'  {name}:={value}')
            print('processes, in start order:')
            for spec, cmd in zip(plan.processes, service.commands(plan, None), strict=True):
                print(f'  [{spec.label}] {shlex.join(cmd)}')
                if spec.problem:
                    print(f'      cannot start: {spec.problem}')
            return 2 if any(spec.problem for spec in plan.processes) else 0
        if args.lockstep:
            import functools

            from mindgrasp_launch.lockstep import launch_lockstep

            return launch_lockstep(service, log=functools.partial(print, flush=True))
        return service.run()
    except LaunchError as exc:
        print(f'mindgrasp launch: error: {exc}', file=sys.stderr)
        return 2
