"""The README's commands, as written: each ``mindgrasp`` line of a code block parses with the
CLI's own parser (options and values as the command expects them), and each ``mindgrasp launch``
line resolves its profile and arguments (``--dry-run``: nothing starts). Lines with placeholders
(``<run>``, ``RUN_DIR``, ``A|B``, ``...``) are the reference card, not commands to paste."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
READMES = [REPO / 'README.md', REPO / 'config' / 'README.md',
           *sorted(REPO.glob('src/*/README.md'))]


def _commands() -> list[tuple[str, str]]:
    """(where, command line) of every pasteable ``mindgrasp`` line in a fenced code block."""
    found = []
    for readme in READMES:
        in_block = False
        for n, line in enumerate(readme.read_text(encoding='utf-8').splitlines(), 1):
            if line.lstrip().startswith('```'):
                in_block = not in_block
                continue
            text = re.split(r'\s#', line)[0].strip()          # drop the trailing comment
            text = text.removesuffix('&').strip()        # a command sent to the background
            if not in_block or not text.startswith('mindgrasp '):
                continue
            if re.search(r'[<>|\[\]]|\.\.\.|\b[A-Z][A-Z_]+\b', text):
                continue                           # a synopsis with placeholders (RUN_DIR, HEAD)
            found.append((f'{readme.relative_to(REPO)}:{n}', text))
    return found


COMMANDS = _commands()


def test_the_readmes_have_commands_to_check() -> None:
    assert len(COMMANDS) >= 20, COMMANDS


@pytest.mark.parametrize(('where', 'line'), [c for c in COMMANDS if ' launch ' not in c[1]])
def test_a_readme_command_parses(where: str, line: str) -> None:
    from mindgrasp_cli.cli import build_parser

    argv = shlex.split(line)[1:]
    try:
        build_parser(argv).parse_args(argv)
    except SystemExit as exc:
        pytest.fail(f'{where}: `{line}` does not parse (exit {exc.code})')


@pytest.mark.parametrize(('where', 'line'), [c for c in COMMANDS if ' launch ' in c[1]])
def test_a_readme_launch_resolves(where: str, line: str, tmp_path) -> None:
    argv = shlex.split(line)[1:]
    run = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *argv, '--dry-run'],
                         capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert run.returncode == 0, f'{where}: `{line}`\n{run.stdout[-2000:]}{run.stderr[-2000:]}'


BENCHMARKS = sorted({m for readme in READMES for m in re.findall(
    r'benchmarks/[a-z_]+\.py', readme.read_text(encoding='utf-8'))})


@pytest.mark.parametrize('script', BENCHMARKS)
def test_a_readme_benchmark_exists_and_answers_help(script: str) -> None:
    run = subprocess.run([sys.executable, str(REPO / script), '--help'], capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0 and 'usage' in run.stdout, f'{script}\n{run.stderr[-2000:]}'
