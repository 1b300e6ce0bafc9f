"""No import circle between the modules of one package, counting the imports inside functions
(issue 41; the checker is ``tests/docs/import_circles.py``)."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from import_circles import import_circles, module_graph

SRC = Path(__file__).resolve().parents[2] / 'src'
PACKAGES = sorted(p for p in SRC.glob('mindgrasp_*/mindgrasp_*') if (p / '__init__.py').is_file())

#: circles left, each with why (the files are another issue's: see the issue 41 report)
KNOWN: dict[tuple[str, ...], str] = {}


@pytest.mark.parametrize('package', PACKAGES, ids=lambda p: p.name)
def test_no_import_circle_within_a_package(package: Path) -> None:
    circles = [c for c in import_circles(package) if tuple(c) not in KNOWN]
    assert not circles, '\n'.join(' <-> '.join(c) for c in circles)


def _write(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / 'pkg' / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root / 'pkg'


def test_the_checker_finds_a_circle_hidden_in_a_function(tmp_path: Path) -> None:
    """A deferred import hides the circle from Python, not from the checker."""
    pkg = _write(tmp_path, {
        '__init__.py': '',
        'a.py': 'from pkg.b import f\n',
        'b.py': 'def f():\n    from pkg import a\n    return a\n',
        'c.py': 'from pkg.sub.d import g\n',
        'sub/__init__.py': '',
        'sub/d.py': 'def g():\n    from .. import c\n',
        'e.py': 'import pkg.a\n',
    })
    assert import_circles(pkg) == [['pkg.a', 'pkg.b'], ['pkg.c', 'pkg.sub.d']]
    assert module_graph(pkg)['pkg.e'] == {'pkg.a'}


def test_type_checking_imports_and_the_package_index_make_no_circle(tmp_path: Path) -> None:
    pkg = _write(tmp_path, {
        '__init__.py': 'from pkg.a import A\n',
        'a.py': 'from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg.b import B\n'
                'class A: ...\n',
        'b.py': 'from pkg.a import A\nclass B(A): ...\n',
    })
    assert import_circles(pkg) == []


def test_cyclonedds_is_imported_only_by_the_dds_modules() -> None:
    """The runtime's DDS layer is ``mindgrasp_ros/runtime/dds/``; nothing else in src/ imports
    cyclonedds (at any depth)."""
    dds = SRC / 'mindgrasp_ros' / 'mindgrasp_ros' / 'runtime' / 'dds'
    found = []
    for path in sorted(SRC.rglob('*.py')):
        if dds in path.parents:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ''] if isinstance(node, ast.ImportFrom) else [])
            if any(n.split('.')[0] == 'cyclonedds' for n in names):
                found.append(f'{path.relative_to(SRC)}:{node.lineno}')
    assert not found, found


def test_the_experiments_domain_imports_nothing_from_its_command_line() -> None:
    """``Experiment``, subjects, engine, records ... (everything but ``cli.py`` and the verbs in
    ``commands/``) import neither, at any depth: the command line only parses and prints, as
    MOABB's evaluations and ros2cli's ``api/`` modules never import their verbs."""
    package = SRC / 'mindgrasp_experiments' / 'mindgrasp_experiments'

    def is_verb(module: str) -> bool:
        return module.endswith('.cli') or '.commands' in module

    graph = module_graph(package)
    found = {m: sorted(t for t in targets if is_verb(t))
             for m, targets in graph.items() if not is_verb(m)}
    assert 'mindgrasp_experiments.experiment' in found
    assert not {m: t for m, t in found.items() if t}, found
