"""One docstring style in src/: numpydoc (``Parameters`` over a ``----------`` rule), as
scikit-learn, MNE and pyRiemann write them; no Google-style ``Args:`` sections (issue 41).
``scripts/google_to_numpydoc.py FILE...`` converts a file."""

from __future__ import annotations

import ast
import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / 'src'
GOOGLE = re.compile(
    r'^[ \t]*(Args|Arguments|Attributes|Raises|Returns|Yields|Examples?|Notes?):\s*$', re.M)
#: files other branches edited in the session that converted the rest: converted after the merge
PENDING = {
    'mindgrasp_bag/mindgrasp_bag/damage.py', 'mindgrasp_bag/mindgrasp_bag/integrity.py',
    'mindgrasp_bag/mindgrasp_bag/latency.py', 'mindgrasp_bag/mindgrasp_bag/mcap_scan.py',
    'mindgrasp_bag/mindgrasp_bag/metadata.py', 'mindgrasp_bag/mindgrasp_bag/reader.py',
    'mindgrasp_bag/mindgrasp_bag/run_stamps.py', 'mindgrasp_eeg/mindgrasp_eeg/bids.py',
    'mindgrasp_eeg/mindgrasp_eeg/robot_motion.py',
    'mindgrasp_experiments/mindgrasp_experiments/records.py',
    'mindgrasp_launch/mindgrasp_launch/rundir.py', 'mindgrasp_launch/mindgrasp_launch/service.py',
    'mindgrasp_launch/mindgrasp_launch/supervisor.py', 'mindgrasp_ros/mindgrasp_ros/node_main.py',
    'mindgrasp_ros/mindgrasp_ros/params.py',
}


def google_sections(path: Path) -> list[str]:
    """``line: header`` of every Google-style section header in the docstrings of ``path``."""
    tree = ast.parse(path.read_text(encoding='utf-8'))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc and node.body:
                start = node.body[0].lineno
                found += [f'{start + doc[:m.start()].count(chr(10))}: {m.group(1)}:'
                          for m in GOOGLE.finditer(doc)]
    return found


def test_docstrings_are_numpydoc() -> None:
    found = [f'{path.relative_to(SRC)}:{hit}' for path in sorted(SRC.rglob('*.py'))
             if path.relative_to(SRC).as_posix() not in PENDING
             for hit in google_sections(path)]
    assert not found, '\n'.join(found)


def test_the_pending_files_are_still_pending() -> None:
    """A converted file leaves the list (so the list only shrinks)."""
    done = sorted(p for p in PENDING if not google_sections(SRC / p))
    assert not done, f'converted, remove from PENDING: {done}'


def test_the_check_finds_a_google_section(tmp_path: Path) -> None:
    sample = tmp_path / 'sample.py'
    sample.write_text('def f(x):\n    """Do.\n\n    Args:\n        x: a value.\n    """\n')
    assert google_sections(sample) == ['4: Args:']
