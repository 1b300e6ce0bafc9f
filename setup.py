"""The root install (``pip install -e .``, scripts/setup.sh): pyproject.toml holds the metadata;
this file adds the ``mindgrasp`` console script and the ``mindgrasp.*`` entry points that each
package registers in its own ``src/mindgrasp_<x>/setup.py`` (the ``mindgrasp`` command discovers
its commands and verbs there, as ``ros2`` does ``ros2cli.command``), so a colcon build and this
install register the same commands from one place.
"""

from __future__ import annotations

import ast
from pathlib import Path

from setuptools import setup

SRC = Path(__file__).resolve().parent / 'src'


def package_entry_points(setup_py: Path) -> dict[str, list[str]]:
    """``{group: ['name = target', ...]}`` of a package's setup.py (read, not executed)."""
    for node in ast.walk(ast.parse(setup_py.read_text(encoding='utf-8'))):
        if isinstance(node, ast.keyword) and node.arg == 'entry_points':
            return ast.literal_eval(node.value)
    return {}


def mindgrasp_entry_points() -> dict[str, list[str]]:
    """The ``mindgrasp.*`` groups of every package, merged, and the ``mindgrasp`` console script
    (the nodes' console scripts stay with colcon, which installs them to ``lib/<package>/``)."""
    groups: dict[str, list[str]] = {'console_scripts': []}
    for setup_py in sorted(SRC.glob('mindgrasp_*/setup.py')):
        for group, items in package_entry_points(setup_py).items():
            if group.startswith('mindgrasp.'):
                groups.setdefault(group, []).extend(items)
            elif group == 'console_scripts':
                groups[group] += [i for i in items if i.partition('=')[0].strip() == 'mindgrasp']
    return groups


if __name__ == '__main__':
    setup(entry_points=mindgrasp_entry_points())
