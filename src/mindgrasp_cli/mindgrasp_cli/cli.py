"""The ``mindgrasp`` command line: ``mindgrasp <command> [<verb>] ...``, in the manner of ``ros2``.

Each command lives in a module that defines ``add_arguments(parser)`` and ``main(args) -> int``.
Packages register their commands themselves, as ros2cli's packages do (``ros2cli.command``,
``ros2topic.verb``): entry points in their setup.py, group ``mindgrasp.command``
(``'launch = mindgrasp_launch.commands.launch'``) for a command without verbs, group
``mindgrasp.verb`` (``'bag record = mindgrasp_bag.commands.bag_record'``) for a command's verb;
several packages may add verbs to one command (``train classifier``, ``train vision``).
Commands and verbs are listed in name order, as ``ros2 --help``. Modules are imported only when
their command runs, so ``mindgrasp --help`` stays fast and one broken package does not break
the others.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import importlib.metadata
import importlib.util
import os
import sys
from collections.abc import Sequence
from pathlib import Path

from mindgrasp_common.cli_checks import OneLineParser
from mindgrasp_ros.process import handle_stop_signals

#: entry point groups: command -> module, and 'command verb' -> module
COMMAND_GROUP = 'mindgrasp.command'
VERB_GROUP = 'mindgrasp.verb'


@functools.cache
def commands() -> dict[str, str | dict[str, str]]:
    """Command -> module, or command -> {verb: module}, from the installed packages' entry
    points, in name order. A name registered twice (an editable install and a colcon workspace
    both on the path) keeps its first registration, as Python's import would."""
    found: dict[str, str | dict[str, str]] = {}
    points = importlib.metadata.entry_points()
    for point in points.select(group=COMMAND_GROUP):
        found.setdefault(point.name, point.module)
    for point in points.select(group=VERB_GROUP):
        command, _, verb = point.name.partition(' ')
        verbs = found.setdefault(command, {})
        if isinstance(verbs, dict) and verb:
            verbs.setdefault(verb, point.module)
    return {name: (target if isinstance(target, str) else dict(sorted(target.items())))
            for name, target in sorted(found.items())}


def _module_file(module_name: str) -> Path | None:
    """The source file of a module, found without importing it or its parent packages (find_spec
    of ``a.b.c`` imports ``a`` and ``a.b``, whose ``__init__`` may pull in numpy and more: the bag
    package's does); None when it is not installed."""
    top, _, rest = module_name.partition('.')
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return None
    if spec is None:
        return None
    if not rest:
        return Path(spec.origin) if spec.origin else None
    for location in spec.submodule_search_locations or []:
        base = Path(location, *rest.split('.'))
        for candidate in (base.with_suffix('.py'), base / '__init__.py'):
            if candidate.is_file():
                return candidate
    return None


@functools.cache
def _module_doc(module_name: str) -> str:
    """Docstring of a command module, without importing heavy packages on --help (read once
    per process: in-process callers such as tests build the parser many times)."""
    origin = _module_file(module_name)
    if origin is None:
        return '(not installed)'
    import ast

    try:
        with open(origin, encoding='utf-8') as f:
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
    for command, target in commands().items():
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
    from mindgrasp_launch.rundir import DIST_NAME, git_info, package_versions

    text = f'mindgrasp {package_versions()[DIST_NAME] or "(not installed)"}'
    describe = git_info().get('describe')
    return f'{text} (git {describe})' if describe else text


#: exit code when the reader of stdout went away (``mindgrasp bag info RUN | head -1``): what a
#: shell reports for a process ended by SIGPIPE (128 + 13), as 130 is for Ctrl-C
EXIT_PIPE_CLOSED = 141


def _prog(argv: Sequence[str]) -> str:
    """``command verb`` of ``argv`` (the words before the first option)."""
    words = []
    for word in argv[:2]:
        if word.startswith('-'):
            break
        words.append(word)
    return ' '.join(words) or 'mindgrasp'


def _os_error_text(exc: OSError) -> str:
    """``<reason>: <file>`` of an OSError, a long file name shortened to 80 characters."""
    name = exc.filename if isinstance(exc.filename, str) else ''
    if len(name) > 80:
        name = f'{name[:40]}...{name[-30:]} ({len(name)} characters)'
    reason = exc.strerror or type(exc).__name__
    return f'{reason}: {name}' if name else reason


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``mindgrasp`` console script.

    Output piped into a reader that stops early (``| head -1``) ends every command quietly
    with :data:`EXIT_PIPE_CLOSED`: Python's recipe (the ``signal`` module's note on SIGPIPE),
    stdout pointed at /dev/null so that the interpreter's last flush cannot raise again.
    """
    try:
        try:
            return _main(argv)
        finally:
            sys.stdout.flush()   # a closed pipe shows here rather than at the interpreter's exit
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return EXIT_PIPE_CLOSED


def _main(argv: Sequence[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if not commands() and argv[:1] != ['--version']:
        # an install older than the packages' setup.py files (pulled, not re-installed)
        print(f'mindgrasp: no commands are installed (no {COMMAND_GROUP!r} or {VERB_GROUP!r} entry '
              f'points on the Python path): run bash scripts/setup.sh in the checkout, or source '
              f'the colcon workspace (install/setup.bash).', file=sys.stderr)
        return 2
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
        verbs = commands().get(args.command, {})  # a command given without its verb
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
    except BrokenPipeError:
        raise                # stdout's reader went away: the entry point's own exit
    except OSError as exc:
        # a path the system cannot use (a name too long, a folder given for a file, no
        # permission, a full disk) that the command did not check itself: one line
        print(f'mindgrasp {_prog(argv)}: error: {_os_error_text(exc)}; check the path and '
              'try again.', file=sys.stderr)
        return 1
