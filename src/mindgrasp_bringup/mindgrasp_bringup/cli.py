"""The ``mindgrasp`` command line: ``mindgrasp <command> [<verb>] ...``, in the manner of ``ros2``.

Each command lives in a module that defines ``add_arguments(parser)`` and ``main(args) -> int``.
Commands with verbs (``bag record``, ``train classifier``) map each verb to such a module, possibly
in another package (``train classifier`` is :mod:`mindgrasp_classifier.train_cli`). Modules are
imported only when their command runs, so ``mindgrasp --help`` stays fast and one broken package
does not break the others.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import importlib.util
import sys
from collections.abc import Sequence

from mindgrasp_common.cli_checks import OneLineParser
from mindgrasp_ros.process import handle_stop_signals

#: command -> module, or command -> {verb: module}
COMMANDS: dict[str, str | dict[str, str]] = {
    'launch': 'mindgrasp_bringup.commands.launch',
    'run': 'mindgrasp_bringup.commands.run',
    'replay': 'mindgrasp_bringup.commands.replay',
    'bag': {
        'record': 'mindgrasp_bag.commands.bag_record',
        'play': 'mindgrasp_bag.commands.bag_play',
        'info': 'mindgrasp_bag.commands.bag_info',
        'reindex': 'mindgrasp_bag.commands.bag_reindex',
        'latency': 'mindgrasp_bag.commands.bag_latency',
    },
    'topic': {
        'list': 'mindgrasp_bringup.commands.topic_list',
        'echo': 'mindgrasp_bringup.commands.topic_echo',
        'hz': 'mindgrasp_bringup.commands.topic_hz',
        'info': 'mindgrasp_bringup.commands.topic_info',
        'pub': 'mindgrasp_bringup.commands.topic_pub',
    },
    'node': {
        'list': 'mindgrasp_bringup.commands.node_list',
        'info': 'mindgrasp_bringup.commands.node_info',
    },
    'service': {
        'list': 'mindgrasp_bringup.commands.service_list',
        'type': 'mindgrasp_bringup.commands.service_type',
        'call': 'mindgrasp_bringup.commands.service_call',
    },
    'interface': {
        'list': 'mindgrasp_bringup.commands.interface_list',
        'show': 'mindgrasp_bringup.commands.interface_show',
        'proto': 'mindgrasp_bringup.commands.interface_proto',
    },
    'param': {
        'list': 'mindgrasp_bringup.commands.param_list',
        'get': 'mindgrasp_bringup.commands.param_get',
        'set': 'mindgrasp_bringup.commands.param_set',
        'describe': 'mindgrasp_bringup.commands.param_describe',
        'dump': 'mindgrasp_bringup.commands.param_dump',
        'load': 'mindgrasp_bringup.commands.param_load',
    },
    'eeg': {
        'virtual-amp': 'mindgrasp_eeg.virtual_amp_cli',
        'play': 'mindgrasp_eeg.player_cli',
        'fit-virtual': 'mindgrasp_experiments.fit_virtual_cli',
    },
    'train': {
        'classifier': 'mindgrasp_classifier.train_cli',
        'vision': 'mindgrasp_vision.train_cli',
    },
    'evaluate': {
        'classifier': 'mindgrasp_classifier.evaluate_cli',
    },
    'experiment': {
        'set-locations': 'mindgrasp_experiments.commands.set_locations',
        'random-locations': 'mindgrasp_experiments.commands.random_locations',
        'report': 'mindgrasp_experiments.commands.report',
        'sweep': 'mindgrasp_experiments.commands.sweep',
    },
    'export': {
        'eeg': 'mindgrasp_eeg.export_cli',
        'bids': 'mindgrasp_eeg.bids_cli',
    },
    'trainer': {
        'schedule': 'mindgrasp_trainer.schedule_cli',
    },
    'session': {
        'run': 'mindgrasp_bringup.session_cli',
        'resume': 'mindgrasp_bringup.session_cli',
        'calibrate': 'mindgrasp_bringup.session_cli',
    },
}


@functools.cache
def _module_doc(module_name: str) -> str:
    """Docstring of a command module, without importing heavy packages on --help (read once
    per process: in-process callers such as tests build the parser many times)."""
    try:
        spec = importlib.util.find_spec(module_name)
    except (ImportError, ValueError):
        spec = None
    if spec is None or spec.origin is None:
        return '(not installed)'
    import ast

    try:
        with open(spec.origin, encoding='utf-8') as f:
            doc = ast.get_docstring(ast.parse(f.read())) or ''
    except (OSError, SyntaxError):
        return ''
    return doc.strip()


def _summary(doc: str) -> str:
    """The first paragraph of ``doc`` on one line (the command list's help)."""
    return ' '.join(doc.split('\n\n')[0].split())


def _add_command(subparsers: argparse._SubParsersAction, name: str, module_name: str) -> None:
    doc = _module_doc(module_name)
    parser = subparsers.add_parser(name, help=_summary(doc), description=doc,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.set_defaults(_module=module_name)
    module = _import(module_name)
    if module is not None:
        module.add_arguments(parser)


def _import(module_name: str):
    try:
        return importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and module_name.startswith(exc.name):
            return None
        raise


def build_parser(argv: Sequence[str]) -> argparse.ArgumentParser:
    """Build the parser; only the command named in ``argv`` imports its module."""
    parser = OneLineParser(
        prog='mindgrasp',
        description='MIndGrasp-ROS: motor-imagery EEG control of an assistive arm on ROS 2.')
    parser.add_argument('--version', action='store_true',
                        help="print the project's version (and git revision) and exit")
    sub = parser.add_subparsers(dest='command', metavar='<command>')
    chosen = argv[0] if argv else None
    for command, target in COMMANDS.items():
        if isinstance(target, str):
            if command == chosen:
                _add_command(sub, command, target)
            else:
                sub.add_parser(command, help=_summary(_module_doc(target)))
            continue
        cmd_parser = sub.add_parser(command, help=f'{command} verbs: ' + ', '.join(target))
        verbs = cmd_parser.add_subparsers(dest='verb', metavar='<verb>')
        for verb, module_name in target.items():
            if command == chosen and len(argv) > 1 and argv[1] == verb:
                _add_command(verbs, verb, module_name)
            else:
                verbs.add_parser(verb, help=_summary(_module_doc(module_name)))
    return parser


def version_text() -> str:
    """``mindgrasp 0.1.0`` and, in a git checkout, ``(git <describe>)``: what every run's
    provenance records."""
    from mindgrasp_bringup.launch_system.rundir import DIST_NAME, git_info, package_versions

    text = f'mindgrasp {package_versions()[DIST_NAME] or "(not installed)"}'
    describe = git_info().get('describe')
    return f'{text} (git {describe})' if describe else text


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``mindgrasp`` console script."""
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    module_name = getattr(args, '_module', None)
    if args.version and module_name is None:
        print(version_text())
        return 0
    if module_name is None:
        if not argv:
            parser.print_help()
            return 0
        verbs = COMMANDS.get(args.command, {})  # a command given without its verb
        print(f'mindgrasp {args.command}: error: a verb is required: {", ".join(verbs)} '
              f'(see mindgrasp {args.command} --help)', file=sys.stderr)
        return 2
    handle_stop_signals()    # Ctrl-C and SIGTERM stop every command, even one run in the background
    module = _import(module_name)
    if module is None:
        print(f'mindgrasp: the command module {module_name!r} is not installed.', file=sys.stderr)
        return 2
    try:
        return int(module.main(args) or 0)
    except KeyboardInterrupt:
        return 130
