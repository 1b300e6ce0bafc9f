"""The ROS command line: ``--ros-args -r from:=to -p name:=value --params-file F --log-level L``.

Parameter files are ROS YAML::

    /**:                     # any node ("/**" wildcard)
      ros__parameters: {use_sim_time: true}
    eeg_acquisition:          # a node name (or /ns/name, or ns: {name: ...})
      ros__parameters:
        stream: {name: MyAmp} # nested keys become "stream.name"
"""

from __future__ import annotations

import fnmatch
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_ros.runtime.exceptions import InvalidNameError, RCLError
from mindgrasp_ros.runtime.logging import parse_severity
from mindgrasp_ros.runtime.names import RemapRule, validate_namespace, validate_node_name

__all__ = ['ParamsFileError', 'RosArgumentError', 'RosArguments', 'load_params_file',
           'parse_ros_args', 'remove_ros_args']


class RosArgumentError(RCLError):
    """A malformed ``--ros-args`` section (rcl's ``RCL_RET_INVALID_ROS_ARGS``): the message
    names the argument and the form it must take. A node given one refuses to start (exit 2)."""


class ParamsFileError(RosArgumentError):
    """A parameter file that is missing or not ROS YAML."""


@dataclass
class RosArguments:
    """What ``--ros-args`` sections of a command line say."""

    remaps: list[RemapRule] = field(default_factory=list)
    #: (node pattern or None for any node, name, value) in command-line order
    params: list[tuple[str | None, str, Any]] = field(default_factory=list)
    params_files: list[Path] = field(default_factory=list)
    log_levels: list[tuple[str, str]] = field(default_factory=list)  # (logger or '', level)
    enclave: str | None = None

    def extend(self, other: RosArguments) -> None:
        self.remaps.extend(other.remaps)
        self.params.extend(other.params)
        self.params_files.extend(other.params_files)
        self.log_levels.extend(other.log_levels)
        self.enclave = other.enclave or self.enclave

    def node_name_override(self, node_name: str) -> str | None:
        for rule in self.remaps:
            if rule.from_ in ('__node', '__name') and rule.applies_to(node_name):
                return rule.to
        return None

    def namespace_override(self, node_name: str) -> str | None:
        for rule in self.remaps:
            if rule.from_ == '__ns' and rule.applies_to(node_name):
                return rule.to
        return None

    def parameters_for(self, node_name: str, namespace: str) -> dict[str, Any]:
        """Parameter overrides for a node: files first, then ``-p`` in order (later wins)."""
        fqn = f'{namespace.rstrip("/")}/{node_name}'
        values: dict[str, Any] = {}
        for path in self.params_files:
            values.update(load_params_file(path, fqn))
        for pattern, name, value in self.params:
            if pattern is None or pattern in (node_name, fqn):
                values[name] = value
        return values


def _parse_value(text: str) -> Any:
    try:
        return yaml.safe_load(text) if text != '' else ''
    except yaml.YAMLError:
        return text


def parse_ros_args(args: list[str]) -> RosArguments:
    """Parse every ``--ros-args ... [--]`` section of ``args``; raise on malformed ones."""
    out = RosArguments()
    i = 0
    inside = False
    while i < len(args):
        arg = args[i]
        if arg == '--ros-args':
            inside = True
            i += 1
            continue
        if not inside:
            i += 1
            continue
        if arg == '--':
            inside = False
            i += 1
            continue

        def need_value(flag: str, index: int) -> str:
            if index + 1 >= len(args):
                msg = f'{flag} needs a value after it (--ros-args {flag} ...).'
                raise RosArgumentError(msg)
            return args[index + 1]

        if arg in ('-r', '--remap'):
            out.remaps.append(_parse_remap(need_value(arg, i)))
            i += 2
        elif arg in ('-p', '--param'):
            text = need_value(arg, i)
            if ':=' not in text:
                msg = f'Invalid parameter {text!r}: write it as -p name:=value.'
                raise RosArgumentError(msg)
            lhs, value = text.split(':=', 1)
            node = None
            if ':' in lhs:
                node, lhs = lhs.split(':', 1)
            if not lhs:
                msg = f'Invalid parameter {text!r}: the name is missing; write -p name:=value.'
                raise RosArgumentError(msg)
            out.params.append((node, lhs, _parse_value(value)))
            i += 2
        elif arg == '--params-file':
            path = Path(need_value(arg, i))
            load_params_file(path, None)  # validate now: fail early with the file named
            out.params_files.append(path)
            i += 2
        elif arg == '--log-level':
            text = need_value(arg, i)
            logger, _, level = text.rpartition(':=')  # "level" or "logger_name:=level"
            try:
                parse_severity(level)
            except ValueError as exc:
                msg = f'--log-level {text!r}: {exc}'
                raise RosArgumentError(msg) from None
            out.log_levels.append((logger, level))
            i += 2
        elif arg in ('-e', '--enclave'):
            out.enclave = need_value(arg, i)
            i += 2
        elif arg in ('--disable-rosout-logs', '--disable-stdout-logs',
                     '--enable-rosout-logs', '--enable-stdout-logs',
                     '--disable-external-lib-logs', '--enable-external-lib-logs'):
            i += 1
        else:
            msg = (f'Unknown ROS argument {arg!r}. Valid: -r from:=to, -p name:=value, '
                   '--params-file FILE, --log-level [logger:=]LEVEL, -e ENCLAVE.')
            raise RosArgumentError(msg)
    return out


def _parse_remap(text: str) -> RemapRule:
    """``-r`` rule -> :class:`RemapRule`; a new node name (``__node:=``) or namespace
    (``__ns:=``) is validated here, so a bad one is an argument error, not a crash later."""
    try:
        rule = RemapRule.parse(text)
        if rule.from_ in ('__node', '__name'):
            validate_node_name(rule.to)
        elif rule.from_ == '__ns':
            validate_namespace(rule.to)
    except InvalidNameError as exc:
        raise RosArgumentError(f'-r {text}: {exc}') from None
    return rule


def remove_ros_args(args: list[str]) -> list[str]:
    """``args`` without the ``--ros-args`` sections (like rclpy.utilities.remove_ros_args)."""
    out: list[str] = []
    inside = False
    for arg in args:
        if arg == '--ros-args':
            inside = True
        elif inside and arg == '--':
            inside = False
        elif not inside:
            out.append(arg)
    return out


def _flatten(prefix: str, value: Any, out: dict[str, Any]) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(f'{prefix}.{k}' if prefix else str(k), v, out)
    else:
        out[prefix] = value


def _collect(node: Any, path: list[str], found: list[tuple[str, dict]], file: Path) -> None:
    if not isinstance(node, dict):
        msg = (f'{file}: {"/".join(path) or "top level"} must be a mapping of node names to '
               '{ros__parameters: {...}}.')
        raise ParamsFileError(msg)
    for key, value in node.items():
        if key == 'ros__parameters':
            if not isinstance(value, dict):
                msg = f'{file}: ros__parameters of {"/".join(path)!r} must be a mapping.'
                raise ParamsFileError(msg)
            found.append(('/'.join(path), value))
        else:
            _collect(value, [*path, str(key).strip('/')], found, file)


_file_cache: dict[tuple[Path, float], list[tuple[str, dict]]] = {}


class _ParamsFileLoader(yaml.SafeLoader):
    """``yaml.safe_load`` plus ``!!python/tuple``, read as a list: launch_ros (Jazzy) writes a
    node's dict parameters with ``yaml.dump``, which tags list values as tuples, and rcl's parser
    ignores tags. Nothing else beyond safe YAML is accepted."""


_ParamsFileLoader.add_constructor('tag:yaml.org,2002:python/tuple',
                                  lambda loader, node: loader.construct_sequence(node))


def _read_params_file(path: Path) -> list[tuple[str, dict]]:
    try:
        mtime = path.stat().st_mtime
    except OSError:
        msg = f'Parameter file {path} does not exist; check the --params-file path.'
        raise ParamsFileError(msg) from None
    key = (path.resolve(), mtime)
    if key not in _file_cache:
        try:
            data = yaml.load(path.read_text(encoding='utf-8'), Loader=_ParamsFileLoader)
        except yaml.YAMLError as exc:
            msg = (f'Parameter file {path} is not valid YAML ({yaml_error_text(exc)}); fix its '
                   'syntax.')
            raise ParamsFileError(msg) from None
        if data is None:
            data = {}
        found: list[tuple[str, dict]] = []
        _collect(data, [], found, path)
        if data and not found:
            msg = (f'Parameter file {path} has no "ros__parameters" section; ROS parameter '
                   'files look like "node_name: {ros__parameters: {name: value}}".')
            raise ParamsFileError(msg)
        _file_cache[key] = found
    return _file_cache[key]


def load_params_file(path: Path, node_fqn: str | None, *,
                     use_wildcard: bool = True) -> dict[str, Any]:
    """Parameters for ``node_fqn`` (``/ns/name``) from a ROS YAML file (all when None).

    ``use_wildcard=False`` leaves out the ``/**`` and ``/*`` sections (``ros2 param load``
    without ``--use-wildcard``).
    """
    values: dict[str, Any] = {}
    for pattern, params in _read_params_file(Path(path)):
        if not use_wildcard and pattern.strip('/') in ('**', '*'):
            continue
        if node_fqn is None or _matches(pattern, node_fqn):
            _flatten('', params, values)
    return values


def _matches(pattern: str, node_fqn: str) -> bool:
    pattern = '/' + pattern.strip('/')
    if pattern in ('/**', '/*'):
        return True
    if pattern == node_fqn:
        return True
    # a bare node name matches that node in any namespace (rcl: only in "/"), wildcards glob
    if '/' not in pattern[1:] and node_fqn.rsplit('/', 1)[-1] == pattern[1:]:
        return True
    return fnmatch.fnmatchcase(node_fqn, pattern.replace('**', '*'))
