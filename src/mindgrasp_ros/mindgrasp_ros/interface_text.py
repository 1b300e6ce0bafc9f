"""Interface definitions as text, for ``mindgrasp interface list|show`` (``ros2 interface``).

The text of a ``.msg``/``.srv`` comes from its file where one is at hand: ``mindgrasp_msgs``, the
service files in ``interface_data``, and ``share/<package>/<kind>/<Name>.<kind>`` of a sourced ROS 2
(``AMENT_PREFIX_PATH``). Other types of the built-in Jazzy store (common_interfaces) have only
their field definitions here: their text is rebuilt from those, so it lacks the file's comments and
default values (``ros2 interface show --no-comments`` prints the same field lines)::

    >>> print(show('geometry_msgs/msg/Point'))
    float64 x
    float64 y
    float64 z
"""

from __future__ import annotations

import os
from pathlib import Path

from mindgrasp_ros.typesupport import (
    EMPTY_PLACEHOLDER,
    MessageTypeError,
    _ros_type_string,
    interface_dir,
    typestore,
)

__all__ = ['interface_names', 'show']

#: rosidl's primitive types: a field of any other type is a nested message
PRIMITIVES = frozenset({'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16',
                        'uint16', 'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring'})


def interface_names() -> dict[str, list[str]]:
    """``{'msg': [...], 'srv': [...], 'action': [...]}``: every ``pkg/kind/Name`` known, sorted."""
    names: dict[str, set[str]] = {'msg': set(), 'srv': set(), 'action': set()}
    for name in typestore().fielddefs:
        package, kind, base = name.split('/')
        if kind == 'srv':
            base = base.removesuffix('_Request').removesuffix('_Response')
        names[kind].add(f'{package}/{kind}/{base}')
    return {kind: sorted(items) for kind, items in names.items()}


def _check(typename: str) -> tuple[str, str, str]:
    parts = typename.split('/')
    if len(parts) != 3 or parts[1] not in ('msg', 'srv', 'action') or not all(parts):
        msg = f"Invalid name '{typename}'; write it as package/msg/Name or package/srv/Name."
        raise MessageTypeError(msg)
    known = interface_names()[parts[1]]
    if typename not in known:
        same = [n.rsplit('/', 1)[1] for n in known if n.startswith(f'{parts[0]}/{parts[1]}/')]
        hint = (f'{parts[0]} has: {", ".join(same)}' if same
                else 'list the known ones with `mindgrasp interface list`')
        raise MessageTypeError(f"Unknown interface '{typename}'; {hint}.")
    return parts[0], parts[1], parts[2]


def _source_file(package: str, kind: str, name: str) -> Path | None:
    """The ``.msg``/``.srv`` file of a type, if one is installed or shipped."""
    from mindgrasp_common.resources import resource_path

    folders = []
    if package == 'mindgrasp_msgs':
        folders.append(interface_dir())
    folders.append(resource_path('mindgrasp_ros', 'interface_data') / package)
    folders += [Path(prefix) / 'share' / package
                for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if prefix]
    for folder in folders:
        path = folder / kind / f'{name}.{kind}'
        if path.is_file():
            return path
    return None


def _rebuilt(name: str) -> list[str]:
    """Field lines of a store type without a file: constants, then fields."""
    consts, fields = typestore().fielddefs[name]
    lines = [f'{ctype} {cname}={value!r}' if ctype == 'string' else f'{ctype} {cname}={value}'
             for cname, ctype, value in consts]
    return lines + [f'{_ros_type_string(desc, msg_syntax=True)} {fname}' for fname, desc in fields
                    if fname != EMPTY_PLACEHOLDER]   # rosidl's member, not the file's


def _lines(package: str, kind: str, name: str) -> list[str]:
    path = _source_file(package, kind, name)
    if path is not None:
        return path.read_text(encoding='utf-8').rstrip('\n').splitlines()
    if kind == 'srv':
        return [*_rebuilt(f'{package}/srv/{name}_Request'), '---',
                *_rebuilt(f'{package}/srv/{name}_Response')]
    return _rebuilt(f'{package}/{kind}/{name}')


def _nested_type(line: str, package: str) -> str | None:
    """``pkg/msg/Name`` of a field line's message type (``None`` for primitives, constants,
    comments and separators)."""
    code = line.split('#', 1)[0].strip()
    tokens = code.split()
    if len(tokens) < 2 or '=' in code:
        return None
    base = tokens[0].split('[', 1)[0].split('<=', 1)[0]
    if base in PRIMITIVES:
        return None
    parts = base.split('/')
    if len(parts) == 1:
        parts = [package, parts[0]]
    return f'{parts[0]}/msg/{parts[-1]}'


def show(typename: str, *, comments: bool = True, nested_comments: bool = False) -> str:
    """The definition as ``ros2 interface show`` prints it: the file's lines, each nested message
    type expanded under its field one tab deeper (without comments unless ``nested_comments``)."""
    package, kind, name = _check(typename)
    out: list[str] = []
    _show(package, kind, name, comments, nested_comments, 0, out)
    return '\n'.join(out)


def _show(package: str, kind: str, name: str, comments: bool, nested_comments: bool,
          depth: int, out: list[str]) -> None:
    for line in _lines(package, kind, name):
        text = line.rstrip()
        if not comments:
            text = text.split('#', 1)[0].rstrip()
            if not text.strip():
                continue
        out.append('\t' * depth + text if text else '')
        nested = _nested_type(line, package)
        if nested is not None:
            sub_package, _, sub_name = nested.split('/')
            _show(sub_package, 'msg', sub_name, nested_comments, nested_comments, depth + 1, out)
