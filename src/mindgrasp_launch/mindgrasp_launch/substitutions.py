"""Substitutions: values resolved when a launch description is executed, as in ``launch``.

A value anywhere a substitution is accepted may be plain text, a :class:`Substitution`, or a list
of both (concatenated), e.g. ``['/robot', LaunchConfiguration('id')]``.
"""

from __future__ import annotations

import ast
import math
import os
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import yaml

from mindgrasp_launch.errors import LaunchError

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext


class Substitution:
    """Base class: ``perform(context) -> str``."""

    def perform(self, context: LaunchContext) -> str:  # pragma: no cover - abstract
        raise NotImplementedError

    def describe(self) -> str:
        """Text shown by ``--show-args`` and error messages."""
        return type(self).__name__


SomeSubstitutions = str | Path | Substitution | Iterable[str | Path | Substitution]


class TextSubstitution(Substitution):
    """Plain text."""

    def __init__(self, *, text: str) -> None:
        self.text = str(text)

    def perform(self, context: LaunchContext) -> str:
        return self.text

    def describe(self) -> str:
        return repr(self.text)


class LaunchConfiguration(Substitution):
    """The value of a launch argument (``name:=value`` on the command line or its default)."""

    def __init__(self, variable_name: str, *, default: SomeSubstitutions | None = None) -> None:
        self.variable_name = variable_name
        self.default = default

    def perform(self, context: LaunchContext) -> str:
        if self.variable_name in context.launch_configurations:
            return context.launch_configurations[self.variable_name]
        if self.default is not None:
            return perform_substitutions(context, self.default)
        known = ', '.join(sorted(context.launch_configurations)) or '(none)'
        msg = (f"launch configuration '{self.variable_name}' does not exist: declare it with "
               f"DeclareLaunchArgument('{self.variable_name}', ...) before using it, or give it "
               f"as {self.variable_name}:=<value>. Known configurations: {known}.")
        raise LaunchError(msg)

    def describe(self) -> str:
        return f'LaunchConfig({self.variable_name!r})'


class EnvironmentVariable(Substitution):
    """An environment variable of the launcher, with an optional default."""

    def __init__(self, name: str, *, default_value: str | None = None) -> None:
        self.name = name
        self.default_value = default_value

    def perform(self, context: LaunchContext) -> str:
        value = os.environ.get(self.name, self.default_value)
        if value is None:
            msg = (f"environment variable '{self.name}' is not set: set it, or give "
                   f"EnvironmentVariable('{self.name}', default_value=...) a default.")
            raise LaunchError(msg)
        return value


class ThisLaunchFileDir(Substitution):
    """The folder of the launch file being resolved."""

    def perform(self, context: LaunchContext) -> str:
        if context.launch_file is None:
            msg = 'ThisLaunchFileDir used outside a launch file: give the path explicitly.'
            raise LaunchError(msg)
        return str(context.launch_file.parent)


class PathJoinSubstitution(Substitution):
    """Path parts joined with ``/``; each part may itself be substitutions."""

    def __init__(self, substitutions: Iterable[SomeSubstitutions]) -> None:
        self.substitutions = list(substitutions)

    def perform(self, context: LaunchContext) -> str:
        return str(Path(*[perform_substitutions(context, s) for s in self.substitutions]))


_SAFE_NAMES = {'true': True, 'false': False, 'True': True, 'False': False, 'None': None,
               'math': math, 'min': min, 'max': max, 'abs': abs, 'int': int, 'float': float,
               'str': str, 'len': len, 'round': round}


class PythonExpression(Substitution):
    """A small Python expression over the concatenated text, e.g. ``['', LaunchConfiguration('n'),
    ' > 2']``. Only literals, operators, ``math`` and a few builtins are available."""

    def __init__(self, expression: SomeSubstitutions) -> None:
        self.expression = expression

    def perform(self, context: LaunchContext) -> str:
        text = perform_substitutions(context, self.expression)
        try:
            tree = ast.parse(text, mode='eval')
            for node in ast.walk(tree):
                if isinstance(node, ast.Attribute) and node.attr.startswith('_'):
                    raise ValueError('private attributes are not allowed')
            value = eval(compile(tree, '<PythonExpression>', 'eval'),
                         {'__builtins__': {}}, dict(_SAFE_NAMES))
        except Exception as exc:
            msg = f'PythonExpression {text!r} cannot be evaluated ({exc}): fix the expression.'
            raise LaunchError(msg) from exc
        return str(value).lower() if isinstance(value, bool) else str(value)


def _equal_texts(left: str, right: str) -> bool:
    """launch's comparison: as booleans when both are 'true'/'false'/'1'/'0', as numbers when
    both are numbers, else as text."""
    booleans = ('true', 'false', '1', '0')
    if left.lower() in booleans and right.lower() in booleans:
        return (left.lower() in ('true', '1')) == (right.lower() in ('true', '1'))
    try:
        return math.isclose(float(left), float(right))
    except ValueError:
        return left == right


class EqualsSubstitution(Substitution):
    """``'true'`` when both sides resolve to equal values (``launch``'s rules: booleans, then
    numbers, then text), else ``'false'``; e.g. ``IfCondition(EqualsSubstitution(
    LaunchConfiguration('amp'), 'virtual'))``."""

    def __init__(self, left: SomeSubstitutions | None, right: SomeSubstitutions | None) -> None:
        self.left = '' if left is None else left
        self.right = '' if right is None else right

    def _equal(self, context: LaunchContext) -> bool:
        return _equal_texts(perform_substitutions(context, self.left),
                            perform_substitutions(context, self.right))

    def perform(self, context: LaunchContext) -> str:
        return str(self._equal(context)).lower()


class NotEqualsSubstitution(EqualsSubstitution):
    """``'true'`` when the two sides differ (the negation of :class:`EqualsSubstitution`)."""

    def perform(self, context: LaunchContext) -> str:
        return str(not self._equal(context)).lower()


class CameraSpec(Substitution):
    """One field (``'width'``, ``'height'`` or ``'rate'``) of a ``WIDTHxHEIGHT@HZ`` text, e.g.
    ``CameraSpec(LaunchConfiguration('camera'), 'width')``: parsed, never evaluated."""

    def __init__(self, value: SomeSubstitutions, field: str) -> None:
        from mindgrasp_launch.launch_args import CAMERA_FIELDS

        if field not in CAMERA_FIELDS:
            msg = f'CameraSpec field {field!r} is unknown; use one of {CAMERA_FIELDS}.'
            raise LaunchError(msg)
        self.value, self.field = value, field

    def perform(self, context: LaunchContext) -> str:
        from mindgrasp_launch.launch_args import CAMERA_FIELDS, parse_camera

        try:
            values = parse_camera(perform_substitutions(context, self.value))
        except ValueError as exc:
            raise LaunchError(str(exc)) from None
        return str(values[CAMERA_FIELDS.index(self.field)])


class SplitArguments(Substitution):
    """In ``arguments=[...]``/``cmd=[...]``: the resolved text split into several arguments with
    shell quoting rules, e.g. ``SplitArguments(LaunchConfiguration('driver_args'))``."""

    def __init__(self, value: SomeSubstitutions) -> None:
        self.value = value

    def perform(self, context: LaunchContext) -> str:
        return perform_substitutions(context, self.value)

    def perform_list(self, context: LaunchContext) -> list[str]:
        """The arguments (shlex rules)."""
        import shlex

        text = self.perform(context)
        try:
            return shlex.split(text)
        except ValueError as exc:
            msg = f'cannot split {text!r} into arguments ({exc}): check the quotes.'
            raise LaunchError(msg) from exc


def normalize(value: SomeSubstitutions) -> list[Substitution]:
    """Turn text, a substitution or a list of both into a list of substitutions."""
    if isinstance(value, (str, Path)):
        return [TextSubstitution(text=str(value))]
    if isinstance(value, Substitution):
        return [value]
    if isinstance(value, (int, float, bool)):
        return [TextSubstitution(text=str(value).lower() if isinstance(value, bool) else
                                 str(value))]
    try:
        items = list(value)
    except TypeError:
        msg = (f'expected text, a Substitution or a list of them, got {type(value).__name__} '
               f'{value!r}.')
        raise LaunchError(msg) from None
    out: list[Substitution] = []
    for item in items:
        out.extend(normalize(item))
    return out


def perform_substitutions(context: LaunchContext, value: SomeSubstitutions) -> str:
    """Resolve ``value`` (text, a substitution or a list of them) to text."""
    return ''.join(s.perform(context) for s in normalize(value))


def is_substitution(value: object) -> bool:
    """True for a substitution or a list holding one (a value that must be resolved)."""
    if isinstance(value, Substitution):
        return True
    if isinstance(value, (list, tuple)):
        return any(isinstance(v, Substitution) for v in value)
    return False


def _parse_value(text: str) -> Any:
    """A substituted parameter value is read as YAML, as launch_ros does ('3' -> 3)."""
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        return text
    if value is None or isinstance(value, dict):
        return text
    if isinstance(value, list) and not all(isinstance(v, (bool, int, float, str)) for v in value):
        return text
    return value


def resolve_parameter_value(context: LaunchContext, value: Any) -> Any:
    """Resolve substitutions in a parameter value (text read as YAML, as launch_ros does)."""
    if is_substitution(value):
        return _parse_value(perform_substitutions(context, value))
    if isinstance(value, Mapping):
        return {str(k): resolve_parameter_value(context, v) for k, v in value.items()}
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, tuple):
        return list(value)
    return value
