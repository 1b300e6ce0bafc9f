"""The ``mindgrasp`` command finds its commands and verbs through entry points that each package
registers in its own setup.py (groups ``mindgrasp.command`` and ``mindgrasp.verb``), as ros2cli's
packages register ``ros2cli.command`` / ``ros2topic.verb``: no central table names the modules of
other packages, and the installed metadata is what the sources declare."""

from __future__ import annotations

import re
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from mindgrasp_cli import cli
from mindgrasp_testing import root_setup

SRC = Path(__file__).resolve().parents[2] / 'src'
#: what ``mindgrasp --help`` listed before the commands became entry points, in name order
COMMANDS = ['bag', 'eeg', 'evaluate', 'experiment', 'export', 'interface', 'launch', 'node',
            'param', 'replay', 'robot', 'run', 'service', 'session', 'topic', 'train', 'trainer']


def _declared() -> dict[str, dict[str, list[str]]]:
    """``{package: {group: [entry, ...]}}``: the mindgrasp groups each setup.py registers."""
    reader = root_setup().package_entry_points
    return {p.parent.name: {group: items for group, items in reader(p).items()
                            if group.startswith('mindgrasp.')}
            for p in sorted(SRC.glob('mindgrasp_*/setup.py'))}


def test_each_package_registers_only_its_own_modules() -> None:
    for package, groups in _declared().items():
        for item in (i for items in groups.values() for i in items):
            module = item.partition('=')[2].strip()
            assert module.split('.')[0] == package, f'{package}/setup.py registers {item!r}'
            assert (SRC / package / Path(*module.split('.'))).with_suffix('.py').is_file(), item


def test_verb_modules_follow_one_naming_scheme() -> None:
    """Every package keeps its verbs in ``<package>/commands/``, one module named after what the
    user types (``mindgrasp bag record`` -> ``commands/bag_record.py``, ``mindgrasp launch`` ->
    ``commands/launch.py``; a module serving all verbs of a command is named after the command:
    ``commands/session.py``), as ros2cli keeps them in ``<package>/verb/``; no ``*_cli.py``."""
    wrong = []
    for package, groups in _declared().items():
        for item in (i for items in groups.values() for i in items):
            name, _, module = (s.strip() for s in item.partition('='))
            words = name.replace('-', '_').split(' ')
            allowed = sorted({f'{package}.commands.{"_".join(words)}',
                              f'{package}.commands.{words[0]}'})
            if module not in allowed:
                wrong.append(f'{package}/setup.py: {item!r} (expected {" or ".join(allowed)})')
    # the command line's own package has ros_cli.py, its ROS helpers (no verb)
    stray = [str(p.relative_to(SRC)) for p in SRC.glob('mindgrasp_*/mindgrasp_*/**/*_cli.py')
             if p.parts[-3] != 'mindgrasp_cli']
    assert not wrong and not stray, '\n'.join([*wrong, *stray])


def test_installed_commands_are_the_declared_ones_in_name_order() -> None:
    """The installed entry points (scripts/setup.sh re-installs when a setup.py changes) are
    those of the sources; the verbs come from several packages (eeg: mindgrasp_eeg and
    mindgrasp_experiments; train: mindgrasp_classifier and mindgrasp_vision)."""
    declared: dict[str, object] = {}
    for groups in _declared().values():
        for item in groups.get(cli.COMMAND_GROUP, []):
            name, _, module = (s.strip() for s in item.partition('='))
            declared[name] = module
        for item in groups.get(cli.VERB_GROUP, []):
            name, _, module = (s.strip() for s in item.partition('='))
            command, verb = name.split(' ')
            declared.setdefault(command, {})[verb] = module
    found = cli.commands()
    assert list(found) == COMMANDS
    assert found == declared, 'the installed entry points are stale: run bash scripts/setup.sh'
    assert list(found['eeg']) == ['fit-virtual', 'play', 'virtual-amp']
    assert found['train'] == {'classifier': 'mindgrasp_classifier.commands.train_classifier',
                              'vision': 'mindgrasp_vision.commands.train_vision'}


def test_cli_names_no_command_module() -> None:
    text = (SRC / 'mindgrasp_cli' / 'mindgrasp_cli' / 'cli.py').read_text(encoding='utf-8')
    code = re.sub(r'""".*?"""', '', text, flags=re.S)   # docstrings may give examples
    named = set(re.findall(r"'(mindgrasp_\w+(?:\.\w+)+)'", code))
    assert not named, f'cli.py names command modules: {sorted(named)}'


@pytest.mark.parametrize(('argv', 'listed'), [
    (['--help'], COMMANDS),
    (['bag', '--help'], ['info', 'latency', 'play', 'record', 'reindex']),
    (['train', '--help'], ['classifier', 'vision']),
])
def test_help_lists_commands_and_verbs_in_order(argv: list[str], listed: list[str]) -> None:
    """The installed command, run as a user runs it."""
    run = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *argv], capture_output=True,
                         text=True, timeout=120, check=False)
    assert run.returncode == 0, run.stderr
    shown = re.findall(r'^    (\S+)', run.stdout.split('<command>' if argv == ['--help']
                                                    else '<verb>')[-1], re.M)
    assert shown == listed, run.stdout


def test_an_install_without_entry_points_says_how_to_fix_it(tmp_path: Path) -> None:
    """The sources and their libraries on the path but no package metadata (a checkout pulled
    and not re-installed): one line naming the fix, not an empty command list."""
    site = Path(sysconfig.get_paths()['purelib'])
    libs = tmp_path / 'libs'      # numpy and yaml without their dist-info
    libs.mkdir()
    for name in ('numpy', 'numpy.libs', 'yaml', '_yaml'):
        if (site / name).exists():
            (libs / name).symlink_to(site / name)
    code = ('import sys; sys.path[:0] = sys.argv[1:]; '
            'from mindgrasp_cli.cli import main; sys.exit(main(["launch", "demo"]))')
    run = subprocess.run([sys.executable, '-S', '-c', code,
                          *(str(p) for p in sorted(SRC.glob('mindgrasp_*'))), str(libs)],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120, check=False)
    assert run.returncode == 2, run.stdout + run.stderr
    (line,) = run.stderr.splitlines()
    assert line.startswith('mindgrasp: no commands are installed') and 'scripts/setup.sh' in line


def test_help_imports_no_command_package() -> None:
    """``mindgrasp --help`` reads the commands' docstrings from their files: no package that
    registers a verb is imported (the bag package's ``__init__`` alone costs 140 ms)."""
    code = ('import sys; from mindgrasp_cli import cli; cli.build_parser(["--help"]); '
            'print(" ".join(sorted(m for m in sys.modules if m.startswith("mindgrasp_"))))')
    run = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                         timeout=120, check=True)
    imported = set(run.stdout.split())
    registering = {module.split('.')[0] for target in cli.commands().values()
                   for module in ([target] if isinstance(target, str) else target.values())}
    assert not imported & (registering - {'mindgrasp_cli'}), sorted(imported)
