"""Node parameters declared once, from a dataclass with units, ranges and descriptions.

Each field of a parameter dataclass is one ROS parameter. :func:`param` attaches what rclpy's
``ParameterDescriptor`` carries (description, unit, range, read-only) to the field, and
:func:`declare_params` turns the dataclass into ``declare_parameter`` calls, builds the validated
instance from the node's parameters (defaults < parameter file < ``-p``), and installs an on-set
callback that applies a live change to that same instance (so every object holding it sees the new
value at once) or refuses it with the reason::

    @dataclass
    class TalkerParams:
        rate: float = param(10.0, 'messages per second', unit='Hz', min=0.1, max=1000.0)
        topic_prefix: str = param('chatter', 'prefix of the topic name')   # read-only
        verbose: bool = param(False, 'log every message', live=True)

        def __post_init__(self) -> None:        # cross-field checks: raise with the fix
            ...

    class Talker(rclpy.node.Node):
        def __init__(self, **kwargs):
            super().__init__('talker', **kwargs)
            self.params = declare_params(self, TalkerParams)

``mindgrasp param describe /talker rate`` (or ``ros2 param describe``) then shows the description,
unit, range and read-only flag; ``mindgrasp param set /talker topic_prefix x`` is refused with
"... is read-only: restart the node to change it". Fields are read-only unless ``live=True``: a
node opts in to each live change it supports.

Works with the real rclpy and with our runtime (rcl_interfaces messages, ``declare_parameter``,
``add_on_set_parameters_callback``).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any, TypeVar

__all__ = ['ParameterError', 'check_value', 'declare_params', 'describe', 'from_mapping',
           'param', 'parameter_type', 'read_yaml_section', 'refuse_undeclared_overrides',
           'type_code']

T = TypeVar('T')

_INT_MAX = 2**63 - 1
_META = 'mindgrasp_param'


class ParameterError(ValueError):
    """A parameter value is invalid; the message names the parameter, the value and the fix."""


@dataclasses.dataclass(frozen=True)
class ParamInfo:
    """What :func:`param` stores in a field's metadata."""

    description: str = ''
    unit: str = ''
    min: float | None = None
    max: float | None = None
    choices: tuple[str, ...] = ()
    live: bool = False

    def text(self) -> str:
        """The descriptor's description: the text with its unit."""
        unit = f' [{self.unit}]' if self.unit else ''
        return f'{self.description}{unit}'

    def constraints(self) -> str:
        """``additional_constraints`` of the descriptor (choices, live or restart)."""
        parts = []
        if self.choices:
            parts.append(f'one of: {", ".join(self.choices)}')
        parts.append('live: applied at once' if self.live
                     else 'read-only: restart the node to change it')
        return '; '.join(parts)


def param(default: Any, description: str = '', *, unit: str = '', min: float | None = None,
          max: float | None = None, choices: Iterable[str] = (), live: bool = False) -> Any:
    """A dataclass field that is a ROS parameter.

    Args:
        default: the default value (lists are copied per instance).
        description: what the parameter does (one line; the unit goes in ``unit``).
        unit: SI unit of the value ('s', 'Hz', 'rad/s', 'm', 'V') or '' for none.
        min, max: inclusive range of a number (the descriptor's FloatingPointRange or
            IntegerRange; a missing bound is unbounded).
        choices: the allowed strings of a string parameter.
        live: the node applies a change while it runs; otherwise the parameter is read-only.
    """

    info = ParamInfo(description, unit, min, max, tuple(choices), live)
    metadata = {_META: info}
    if isinstance(default, (list, dict)):
        return dataclasses.field(default_factory=lambda: copy.deepcopy(default),
                                 metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


def _info(field: dataclasses.Field) -> ParamInfo:
    return field.metadata.get(_META, ParamInfo())


def parameter_type(field: dataclasses.Field, default: Any) -> Any:
    """The ``rclpy.Parameter.Type`` of a field, from its default (its annotation for an empty
    list)."""
    from mindgrasp_ros import rclpy

    ptype = rclpy.parameter.Parameter.Type
    if isinstance(default, bool):
        return ptype.BOOL
    if isinstance(default, int):
        return ptype.INTEGER
    if isinstance(default, float):
        return ptype.DOUBLE
    if isinstance(default, str):
        return ptype.STRING
    if isinstance(default, list):
        annotation = str(field.type)
        items = default or [None]
        if isinstance(items[0], bool) or 'bool' in annotation:
            return ptype.BOOL_ARRAY
        if isinstance(items[0], int) or 'list[int]' in annotation:
            return ptype.INTEGER_ARRAY
        if isinstance(items[0], float) or 'float' in annotation:
            return ptype.DOUBLE_ARRAY
        return ptype.STRING_ARRAY
    msg = (f"The parameter '{field.name}' has a default of type {type(default).__name__}; a ROS "
           'parameter is a bool, int, float, str or a list of one of them.')
    raise ParameterError(msg)


def type_code(kind: Any) -> int:
    """The ``rcl_interfaces/ParameterType`` number of a ``Parameter.Type`` member.

    Real rclpy's ``Parameter.Type`` is a plain ``Enum`` whose ``value`` is that number (``int()``
    of it raises ``TypeError``); our runtime's is an ``IntEnum``. ``.value`` serves both.
    """
    return int(getattr(kind, 'value', kind))


def describe(cls: type) -> dict[str, tuple[Any, Any]]:
    """``{name: (default, ParameterDescriptor)}`` for every field of the dataclass ``cls``."""
    from mindgrasp_ros import rclpy
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import (
        FloatingPointRange,
        IntegerRange,
        ParameterDescriptor,
    )

    ptype = rclpy.parameter.Parameter.Type
    defaults = cls()
    out = {}
    for field, name, default in _flat_fields(cls, defaults):
        info = _info(field)
        kind = parameter_type(field, default)
        desc = ParameterDescriptor(name=name, type=type_code(kind), description=info.text(),
                                   additional_constraints=info.constraints(),
                                   read_only=not info.live)
        if info.min is not None or info.max is not None:
            if kind == ptype.DOUBLE:
                desc.floating_point_range = [FloatingPointRange(
                    from_value=float(-math.inf if info.min is None else info.min),
                    to_value=float(math.inf if info.max is None else info.max), step=0.0)]
            elif kind == ptype.INTEGER:
                desc.integer_range = [IntegerRange(
                    from_value=int(-_INT_MAX if info.min is None else info.min),
                    to_value=int(_INT_MAX if info.max is None else info.max), step=0)]
        out[name] = (default, desc)
    return out


def _flat_fields(cls: type, instance: Any) -> list[tuple[dataclasses.Field, str, Any]]:
    """``(field, parameter name, value)``; a dict field is one parameter per key
    (``colour_ranges.red``), as ROS parameter files nest them."""
    out = []
    for field in dataclasses.fields(cls):
        value = getattr(instance, field.name)
        if isinstance(value, dict):
            out += [(field, f'{field.name}.{key}', item) for key, item in value.items()]
        else:
            out.append((field, field.name, value))
    return out


def _nest(cls: type, values: Mapping[str, Any], base: Any = None) -> dict[str, Any]:
    """Flat parameter names back to field values: ``colour_ranges.red`` into its dict (the
    other keys from ``base``)."""
    fields = {f.name for f in dataclasses.fields(cls)}
    out: dict[str, Any] = {}
    for name, value in values.items():
        head, _, key = name.partition('.')
        if key and head in fields:
            if head not in out:
                out[head] = dict(getattr(base, head)) if base is not None else {}
            out[head][key] = value
        else:
            out[name] = value
    return out


def check_value(cls: type, name: str, value: Any) -> None:
    """Raise :class:`ParameterError` when ``value`` is outside the range or choices of ``name``."""
    field = {f.name: f for f in dataclasses.fields(cls)}[name.partition('.')[0]]
    info = _info(field)
    unit = f' {info.unit}' if info.unit else ''
    if info.choices and value not in info.choices:
        msg = (f"The parameter '{name}' is {value!r}; use one of {', '.join(info.choices)}.")
        raise ParameterError(msg)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        lo = -math.inf if info.min is None else info.min
        hi = math.inf if info.max is None else info.max
        if not (lo <= value <= hi):   # also refuses NaN
            msg = (f"The parameter '{name}' must be within [{lo:g}, {hi:g}]{unit}; "
                   f'{value!r} is invalid.')
            raise ParameterError(msg)


def from_mapping(cls: type[T], values: Mapping[str, Any]) -> T:
    """Build ``cls`` from ``name -> value`` with ranges and choices checked, then the dataclass'
    own validation (``__post_init__``, which raises a ``ValueError`` subclass naming the fix).
    Raises :class:`ParameterError` naming the problem."""
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(values) - names)
    if unknown:
        msg = f'Unknown parameter(s) {unknown}; the parameters are: {", ".join(sorted(names))}.'
        raise ParameterError(msg)
    for name, value in values.items():
        items = value.values() if isinstance(value, dict) else [value]
        for item in items:
            check_value(cls, name, item)
    try:
        return cls(**values)
    except ParameterError:
        raise
    except ValueError as exc:   # the dataclass' checks (a package error class is a ValueError)
        raise ParameterError(str(exc)) from exc


def declare_params(node: Any, cls: type[T], *,
                   on_change: Callable[[T, set[str]], None] | None = None) -> T:
    """Declare every field of the dataclass ``cls`` on ``node``; return the validated instance.

    The values come from the node's overrides (parameter files, ``-p``); an invalid value raises
    :class:`ParameterError` (``run_node`` ends the node with exit code 2 and the message). Later
    ``set_parameters`` calls go through an on-set callback: read-only fields are refused by their
    descriptor; live ones are checked on a copy (ranges, choices, ``__post_init__``), then
    ``on_change(candidate, names)`` may rebuild what depends on them (raise a ``ValueError`` to
    refuse the change with its message); on success the new values are written into the returned
    instance in place, so every object holding it sees them at once.
    """
    from mindgrasp_ros import rclpy

    specs = describe(cls)
    ptype = rclpy.parameter.Parameter.Type
    for name, (default, desc) in specs.items():
        if isinstance(default, list) and not default:
            _declare_empty_list(node, name, ptype(desc.type), desc)
        else:
            node.declare_parameter(name, default, desc)
    values = {name: _python(node.get_parameter(name).value, specs[name][0]) for name in specs}
    instance = from_mapping(cls, _nest(cls, values))

    def callback(params: list) -> Any:
        from mindgrasp_ros.interfaces.rcl_interfaces.msg import SetParametersResult

        changes = {p.name: _python(p.value, specs[p.name][0]) for p in params if p.name in specs}
        if not changes:
            return SetParametersResult(successful=True)
        fixed = sorted(n for n in changes if specs[n][1].read_only)
        if fixed:   # rclpy refuses these before the callback; said here for any runtime
            return SetParametersResult(
                successful=False,
                reason=f"'{fixed[0]}' is read-only: restart the node to change it.")
        nested = _nest(cls, changes, instance)
        current = {f.name: getattr(instance, f.name) for f in dataclasses.fields(cls)}
        try:
            candidate = from_mapping(cls, {**current, **nested})
            if on_change is not None:
                on_change(candidate, set(nested))
        except ValueError as exc:   # ParameterError and the packages' errors
            return SetParametersResult(successful=False, reason=str(exc))
        for name in nested:
            setattr(instance, name, getattr(candidate, name))
        node.get_logger().info(
            'Parameter change applied: ' + ', '.join(f'{k}={v!r}' for k, v in changes.items()))
        return SetParametersResult(successful=True)

    node.add_on_set_parameters_callback(callback)
    return instance


def _declare_empty_list(node: Any, name: str, kind: Any, desc: Any) -> None:
    """Declare a parameter whose default is an empty list of type ``kind``: an empty list
    has no type of its own, so the type goes with it as a ``ParameterValue``. rclpy 7.1.3 (Jazzy)
    cannot take that (``TypeError``); there it is declared by its type, set to ``[]`` of that
    type when no override gave a value (writable until then), then made read-only if it is."""
    from mindgrasp_ros import rclpy

    Parameter = rclpy.parameter.Parameter   # noqa: N806 - rclpy's class
    try:
        node.declare_parameter(name, Parameter(name, kind, []).get_parameter_value(), desc)
    except TypeError:
        writable = copy.deepcopy(desc)
        writable.read_only = False
        node.declare_parameter(name, kind, writable)
        if node.get_parameter_or(name).type_ == Parameter.Type.NOT_SET:
            node.set_parameters([Parameter(name, kind, [])])
        node.set_descriptor(name, desc)


def _python(value: Any, default: Any) -> Any:
    """A parameter value as the dataclass field's Python type (lists, floats from ints)."""
    if isinstance(default, bool):
        return bool(value)
    if isinstance(default, float) and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if isinstance(default, list) and value is not None:
        return list(value)
    return value


def read_yaml_section(path: str | Path, node_name: str) -> dict[str, Any]:
    """The ``<node_name>: ros__parameters:`` (or ``/**``) mapping of a ROS parameter file."""
    import yaml

    from mindgrasp_common.cli_checks import yaml_error_text

    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8')) or {}
    except (OSError, yaml.YAMLError) as exc:
        msg = (f'Cannot read the parameter file {path}: {yaml_error_text(exc)}. Give a ROS '
               'parameter YAML file.')
        raise ParameterError(msg) from exc
    for key in (node_name, f'/{node_name}', '/**'):
        section = data.get(key)
        if isinstance(section, dict) and 'ros__parameters' in section:
            return dict(section['ros__parameters'] or {})
    msg = f"{path} has no '{node_name}: ros__parameters:' section; add one."
    raise ParameterError(msg)


#: override keys a node may receive without declaring them: rclpy declares ``qos_overrides.*``
#: only for publishers that opt in, and ignores the others
_TOLERATED_PREFIXES = ('qos_overrides.',)


def refuse_undeclared_overrides(node: Any) -> None:
    """Raise :class:`ParameterError` when the node's parameter files or ``-p`` name a parameter
    it did not declare (``lock_durtion`` for ``lock_duration``), naming the key and the declared
    names closest to it; nothing for a node made with ``allow_undeclared_parameters`` or
    ``automatically_declare_parameters_from_overrides``.

    rclpy keeps such an override unused and raises ``ParameterNotDeclaredException`` only when
    code asks for the name, so a typo in a parameter file was silently ignored and the node ran
    on its default. ``run_node`` calls this once the node is constructed (every parameter is
    declared then): exit 2 and one line.
    """
    import difflib

    if getattr(node, '_allow_undeclared', False) or getattr(
            node, '_allow_undeclared_parameters', False):
        return
    # ours keeps the overrides in ``_overrides``, rclpy in ``_parameter_overrides``
    overrides = getattr(node, '_overrides', None)
    if overrides is None:
        overrides = getattr(node, '_parameter_overrides', {}) or {}
    unknown = sorted(name for name in overrides if not node.has_parameter(name)
                     and not name.startswith(_TOLERATED_PREFIXES))
    if not unknown:
        return
    declared = sorted(getattr(node, '_parameters', {}))
    name = unknown[0]
    close = difflib.get_close_matches(name, declared, n=3, cutoff=0.6)
    hint = (f"did you mean {' or '.join(repr(c) for c in close)}?" if close
            else f"it declares {', '.join(declared[:12])}{', ...' if len(declared) > 12 else ''}")
    more = f' (and {len(unknown) - 1} more: {", ".join(unknown[1:4])})' if len(unknown) > 1 else ''
    msg = (f"Parameter {name!r}{more} is not declared by node '{node.get_name()}' ({hint}); fix "
           'the name in the parameter file or -p (`mindgrasp param list` lists a running node\'s '
           'parameters).')
    raise ParameterError(msg)
