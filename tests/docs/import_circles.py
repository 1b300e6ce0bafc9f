"""Import circles between the modules of one package, counting the imports inside functions.

A deferred import (``def f(): from pkg.b import x``) hides a circle from Python, not from a
reader: to understand ``pkg.a`` one still has to read ``pkg.b``, which needs ``pkg.a``. This
checker reads every ``import`` statement of a package's modules (at any depth: module level,
methods, functions) with :mod:`ast` and finds the strongly connected components of the module
graph (Tarjan's algorithm), so every module of a circle is named. Imports under
``if TYPE_CHECKING:`` are left out: they name a type for annotations and never run (rclpy's
entity modules name ``Node`` that way).

An edge goes to the module a statement names: ``from pkg.sub import name`` is an edge to
``pkg.sub.name`` when that is a module, else to ``pkg.sub``; ``import pkg.sub`` to ``pkg.sub``.
A package's ``__init__`` that Python runs on the way is not counted (it is the package's index,
and importing ``pkg.sub`` from ``pkg/__init__.py`` is the usual way to re-export).

    python tests/docs/import_circles.py src/mindgrasp_ros/mindgrasp_ros   # one line per circle
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

__all__ = ['import_circles', 'module_graph']


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix('').parts)
    if parts[-1] == '__init__':
        parts.pop()
    return '.'.join(parts)


def _imports(tree: ast.AST) -> list[ast.Import | ast.ImportFrom]:
    """Every import statement of ``tree`` outside ``if TYPE_CHECKING:`` blocks."""
    found: list[ast.Import | ast.ImportFrom] = []
    todo = [tree]
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            found.append(node)
            continue
        if isinstance(node, ast.If) and 'TYPE_CHECKING' in ast.unparse(node.test):
            todo.extend(node.orelse)
            continue
        todo.extend(ast.iter_child_nodes(node))
    return found


def module_graph(package_dir: Path) -> dict[str, set[str]]:
    """Module -> the modules of the same package it imports (anywhere in its code).

    Parameters
    ----------
    package_dir : Path
        The package's folder (the one holding its ``__init__.py``).

    Returns
    -------
    dict of str to set of str
        Dotted module names; every module of the package is a key.
    """
    package_dir = Path(package_dir)
    modules = {_module_name(p, package_dir): p for p in sorted(package_dir.rglob('*.py'))}
    top = package_dir.name
    graph: dict[str, set[str]] = {name: set() for name in modules}
    for name, path in modules.items():
        is_package = path.name == '__init__.py'
        for node in _imports(ast.parse(path.read_text(encoding='utf-8'), str(path))):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ''
                if node.level:   # relative: from the module's own package upwards
                    anchor = name.split('.') if is_package else name.split('.')[:-1]
                    anchor = anchor[:len(anchor) - node.level + 1]
                    base = '.'.join([*anchor, *([base] if base else [])])
                targets = [f'{base}.{alias.name}' if f'{base}.{alias.name}' in modules else base
                           for alias in node.names]
            for target in targets:
                if target.split('.')[0] != top:
                    continue
                while target and target not in modules:   # pkg.mod.attr -> pkg.mod
                    target = target.rpartition('.')[0]
                if target and target != name:
                    graph[name].add(target)
    return graph


def import_circles(package_dir: Path) -> list[list[str]]:
    """The import circles of one package: each a sorted list of the modules in it.

    Parameters
    ----------
    package_dir : Path
        The package's folder (the one holding its ``__init__.py``).

    Returns
    -------
    list of list of str
        One entry per strongly connected component of more than one module, sorted.
    """
    graph = module_graph(package_dir)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles: list[list[str]] = []

    def visit(v: str) -> None:   # Tarjan; the graphs are small (< 100 modules), recursion is fine
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                circles.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(circles)


def main(argv: list[str]) -> int:
    found = 0
    for arg in argv:
        for circle in import_circles(Path(arg)):
            print(' <-> '.join(circle))
            found += 1
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
