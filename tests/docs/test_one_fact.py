"""One fact in one place (issue 41): the shipped robots are listed by the robot registry only,
and every help text that names them asks it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from mindgrasp_common.robot_description import robot_choices, robot_names

SRC = Path(__file__).resolve().parents[2] / 'src'


def _hand_written_robot_lists(path: Path, names: list[str], root: Path = SRC.parent) -> list[str]:
    """String constants of ``path`` (docstrings left out: they show examples) that name two
    shipped robots or more: a list someone wrote by hand."""
    tree = ast.parse(path.read_text(encoding='utf-8'))
    docstrings = {id(node.value) for node in ast.walk(tree) if isinstance(node, ast.Expr)
                  and isinstance(node.value, ast.Constant)}
    found = []
    for node in ast.walk(tree):
        if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                and id(node) not in docstrings):
            named = [n for n in names if re.search(rf'\b{re.escape(n)}\b', node.value)]
            if len(named) >= 2:
                found.append(f'{path.relative_to(root)}:{node.lineno}: {node.value!r}')
    return found


def test_help_texts_take_the_robot_list_from_the_registry() -> None:
    names = robot_names()
    assert {'mindgrasp_arm', 'panda', 'xarm6'} <= set(names)
    found = [hit for path in sorted(SRC.rglob('*.py'))
             for hit in _hand_written_robot_lists(path, names)]
    assert not found, '\n'.join(found)


def test_the_robot_choices_name_every_shipped_robot() -> None:
    text = robot_choices()
    assert all(name in text for name in robot_names()) and text.endswith('YAML path')


def test_the_check_finds_a_list_written_by_hand(tmp_path: Path) -> None:
    sample = tmp_path / 'sample.py'
    sample.write_text('"""mindgrasp_arm, xarm6 (an example)."""\n'
                      "HELP = 'the arm: mindgrasp_arm, xarm6 or a path'\n")
    hits = _hand_written_robot_lists(sample, ['mindgrasp_arm', 'panda', 'xarm6'], tmp_path)
    assert [h.split(': ', 1)[0] for h in hits] == ['sample.py:2']
