"""ROS 2 parameter files: reading, matching node names (``/**``, ``*``), merging and writing.

A parameter file maps node names to ``ros__parameters`` (nested maps are parameter namespaces)::

    /**:                       # every node
      ros__parameters: {use_sim_time: false}
    classifier:                # the node /classifier (``/**/classifier``: in any namespace)
      ros__parameters:
        window: {length_s: 2.0}
"""

from __future__ import annotations

import contextlib
import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.resources import ResourceNotFoundError, resource_path
from mindgrasp_launch.errors import LaunchError

PARAMS_KEY = 'ros__parameters'
_SCALARS = (bool, int, float, str, bytes)


def load_parameter_file(path: str | Path) -> dict[str, dict[str, Any]]:
    """Read a ROS parameter file into ``{node_key: {dotted.param: value}}``.

    Nested node keys (``ns: node: ros__parameters``) are joined with '/'.
    """
    path = Path(path)
    if not path.is_file():
        msg = f'parameter file {path} does not exist: check the path given in parameters=[...].'
        raise LaunchError(msg)
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8'))
    except yaml.YAMLError as exc:
        msg = f'parameter file {path} is not valid YAML ({yaml_error_text(exc)}); fix the file.'
        raise LaunchError(msg) from exc
    if data is None:
        return {}
    if not isinstance(data, dict):
        msg = (f'parameter file {path} must map node names to ros__parameters, e.g. '
               f'"my_node: {{ros__parameters: {{rate: 10}}}}"; it holds a {type(data).__name__}.')
        raise LaunchError(msg)
    out: dict[str, dict[str, Any]] = {}

    def walk(prefix: str, node: Mapping[str, Any]) -> None:
        for key, value in node.items():
            if key == PARAMS_KEY:
                if not isinstance(value, dict):
                    msg = f'parameter file {path}: ros__parameters of {prefix!r} must be a map.'
                    raise LaunchError(msg)
                out.setdefault(prefix, {}).update(flatten(value))
            elif isinstance(value, dict):
                walk(f'{prefix}/{str(key).strip("/")}' if prefix else str(key), value)
            else:
                msg = (f'parameter file {path}: {prefix + "/" if prefix else ""}{key} is not '
                       f'under ros__parameters; put parameters in "<node>: ros__parameters:".')
                raise LaunchError(msg)

    walk('', data)
    return out


def flatten(params: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    """``{'a': {'b': 1}}`` -> ``{'a.b': 1}`` (ROS parameter namespaces)."""
    out: dict[str, Any] = {}
    for key, value in params.items():
        name = f'{prefix}.{key}' if prefix else str(key)
        if isinstance(value, Mapping):
            out.update(flatten(value, name))
        else:
            out[name] = value
    return out


def unflatten(params: Mapping[str, Any]) -> dict[str, Any]:
    """``{'a.b': 1}`` -> ``{'a': {'b': 1}}``, the form ``ros2 param dump`` writes."""
    out: dict[str, Any] = {}
    for name in sorted(params):
        parts = name.split('.')
        node = out
        for part in parts[:-1]:
            child = node.setdefault(part, {})
            if not isinstance(child, dict):  # 'a' and 'a.b' both set: keep the dotted name
                node = None
                break
            node = child
        if node is None:
            out[name] = params[name]
        else:
            node[parts[-1]] = params[name]
    return out


def _key_regex(key: str) -> re.Pattern[str]:
    key = key if key.startswith('/') else '/' + key
    parts = [p for p in key.split('/') if p]
    pattern = ''
    for part in parts:
        if part == '**':
            pattern += r'(/[^/]+)*'
        else:
            pattern += '/' + re.escape(part).replace(r'\*', '[^/]+')
    return re.compile(pattern + '$')


def node_matches(key: str, fully_qualified_name: str | None) -> bool:
    """Whether a parameter-file node key applies to a node.

    ``/**`` (or ``**``) applies to every node; ``name`` (same as ``/name``) to that node in the
    root namespace, ``/**/name`` in any namespace, ``/ns/name`` in ``/ns``; ``*`` matches one
    name token; as rcl matches them. A node whose name is not known
    (no ``name=`` in the launch description) takes only the all-node keys.
    """
    if key.strip('/') in ('**', ''):
        return True
    if fully_qualified_name is None:
        return False
    return bool(_key_regex(key).match(fully_qualified_name))


def check_value(node: str, name: str, value: Any) -> Any:
    """A ROS parameter value: bool, int, float, str, bytes or a homogeneous list of those."""
    if isinstance(value, _SCALARS):
        return value
    if isinstance(value, (list, tuple)):
        kinds = {bool if isinstance(v, bool) else float if isinstance(v, (int, float))
                 and not isinstance(v, bool) and any(isinstance(x, float) for x in value)
                 else type(v) for v in value}
        if all(isinstance(v, _SCALARS) for v in value) and len(kinds) <= 1:
            return [float(v) if kinds == {float} else v for v in value]
    msg = (f"parameter '{name}' of node {node} has the value {value!r}, which ROS parameters "
           f"cannot hold: use a bool, int, float, string or a list of one of those.")
    raise LaunchError(msg)


def dump_parameters(per_node: Mapping[str, Mapping[str, Any]]) -> str:
    """ROS YAML text: ``{node_key: {ros__parameters: nested params}}``."""
    doc = {node: {PARAMS_KEY: unflatten(params)} for node, params in per_node.items()}
    return yaml.safe_dump(doc, sort_keys=False, default_flow_style=None, width=100)


#: the package whose ``param/<name>.yaml`` holds the parameters of each name; names not listed
#: (launch profiles: demo, hardware, replay, ...) are files of mindgrasp_bringup
PARAMETER_FILE_OWNERS: dict[str, str] = {
    name: f'mindgrasp_{name}' for name in ('eeg', 'classifier', 'vision', 'fsm', 'sim', 'trainer')}


def config_files(*names: str) -> list[Path]:
    """The existing parameter files among ``<package>/param/<name>.yaml``, in order.

    Launch files pass them first in ``parameters=[...]`` (later entries win); a name without a
    parameter file (a profile without overrides) is skipped, so its nodes run on their defaults.
    The files named in ``$MINDGRASP_PARAMS_FILES`` follow (``mindgrasp session`` passes each
    phase's settings so).
    """
    files = []
    for name in names:
        package = PARAMETER_FILE_OWNERS.get(name, 'mindgrasp_bringup')
        with contextlib.suppress(ResourceNotFoundError):
            files.append(resource_path(package, 'param', f'{name}.yaml'))
    # extra ROS parameter files (os.pathsep-separated), e.g. a session phase's settings; each
    # node reads its own section of them, after the package defaults
    extra = [Path(f) for f in os.environ.get('MINDGRASP_PARAMS_FILES', '').split(os.pathsep) if f]
    return files + extra
