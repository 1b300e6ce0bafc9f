"""Launch arguments that must be numbers, checked before any process starts.

``launch``'s ``DeclareLaunchArgument`` knows ``choices`` but no type: a ``seed:=abc`` reached
every node, which then crashed with a traceback. :func:`number_argument` declares a whole number
or a finite number with an optional lower bound; under ``mindgrasp launch`` a bad value is one
line naming the argument, the value and an example, exit 2, nothing started::

    number_argument('seed', default_value='0', description='layout seed', minimum=0)

:func:`file_argument` does the same for a file (``model:=``): when given, it must exist.
:func:`checked_argument` takes the check from the package that reads the value (``eeg_source:=``
is checked by ``mindgrasp_eeg``'s own parser of it).

Under ``ros2 launch`` they are plain ``DeclareLaunchArgument`` s (the nodes' parameter descriptors
check the value there).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
from mindgrasp_launch.actions.declare_launch_argument import (
    DeclareLaunchArgument,
)
from mindgrasp_launch.errors import LaunchError

__all__ = ['CheckedLaunchArgument', 'FileLaunchArgument', 'NumberLaunchArgument',
           'PinCheckArgument', 'check_number', 'checked_argument', 'file_argument',
           'number_argument', 'pin_check_argument']


def check_number(name: str, text: str, kind: type, minimum: float | None,
                 maximum: float | None = None) -> None:
    """Raise :class:`LaunchError` unless ``text`` is a ``kind`` (int or float) within
    ``minimum``..``maximum`` (either bound may be None)."""
    what = 'a whole number' if kind is int else 'a number'
    if minimum is not None and maximum is not None:
        what += f' from {minimum:g} to {maximum:g}'
    elif minimum is not None:
        what += f' >= {minimum:g}'
    elif maximum is not None:
        what += f' <= {maximum:g}'
    if kind is int:
        example = f'{name}:={max(int(minimum or 0), 3)}'
    else:
        example = f'{name}:={(minimum + maximum) / 2:g}' if None not in (minimum, maximum) \
            else f'{name}:=1.5'
    try:
        value = kind(text.strip())
        ok = math.isfinite(value) and (minimum is None or value >= minimum) and (
            maximum is None or value <= maximum)
    except ValueError:
        ok = False
    if not ok:
        msg = f"launch argument '{name}' is {text!r}: {what} is expected, e.g. {example}."
        raise LaunchError(msg)


class NumberLaunchArgument(DeclareLaunchArgument):
    """A :class:`DeclareLaunchArgument` whose value must be a number (checked when declared)."""

    def __init__(self, name: str, *, kind: type = int, minimum: float | None = None,
                 maximum: float | None = None, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.kind, self.minimum, self.maximum = kind, minimum, maximum

    def execute(self, context: Any) -> None:
        super().execute(context)
        check_number(self.name, context.launch_configurations[self.name], self.kind,
                     self.minimum, self.maximum)


def number_argument(name: str, *, default_value: str, description: str, kind: type = int,
                    minimum: float | None = None, maximum: float | None = None) -> Any:
    """Declare ``name`` as a number argument (see the module docstring)."""
    from mindgrasp_launch import launch_api

    if launch_api.using_real_launch():
        return launch_api.DeclareLaunchArgument(name, default_value=default_value,
                                                description=description)
    return NumberLaunchArgument(name, kind=kind, minimum=minimum, maximum=maximum,
                                default_value=default_value, description=description)


def _is_file(text: str) -> bool:
    """``text`` names an existing file: a path (absolute or from the working directory) or a
    ``package://<package>/<path>`` URI."""
    try:
        return resolve_path(text, 'mindgrasp_bringup').is_file()
    except ResourceNotFoundError:
        return False


class FileLaunchArgument(DeclareLaunchArgument):
    """A :class:`DeclareLaunchArgument` naming a file: empty (the default) or an existing file,
    relative to the working directory, or a ``package://<package>/<path>`` URI."""

    def execute(self, context: Any) -> None:
        super().execute(context)
        text = context.launch_configurations[self.name].strip()
        if text and not _is_file(text):
            msg = (f"launch argument '{self.name}' is {text!r}, which is not a file; give the "
                   f'path of an existing file ({self.description}).')
            raise LaunchError(msg)


def file_argument(name: str, *, default_value: str, description: str) -> Any:
    """Declare ``name`` as a file argument (see the module docstring)."""
    from mindgrasp_launch import launch_api

    if launch_api.using_real_launch():
        return launch_api.DeclareLaunchArgument(name, default_value=default_value,
                                                description=description)
    return FileLaunchArgument(name, default_value=default_value, description=description)


class CheckedLaunchArgument(DeclareLaunchArgument):
    """A :class:`DeclareLaunchArgument` whose value ``check(text)`` accepts; whatever the check
    raises becomes a :class:`LaunchError` naming the argument (before any process starts)."""

    def __init__(self, name: str, *, check: Callable[[str], object], **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.check = check

    def execute(self, context: Any) -> None:
        super().execute(context)
        text = context.launch_configurations[self.name]
        try:
            self.check(text)
        except Exception as exc:  # the check's own error class; its message says what is valid
            msg = f"launch argument '{self.name}' is {text!r}: {exc}"
            raise LaunchError(msg) from None


def checked_argument(name: str, *, check: Callable[[str], object], default_value: str,
                     description: str) -> Any:
    """Declare ``name`` with a value check (see the module docstring): ``check(text)`` raises
    with a message naming the valid values when ``text`` is not one."""
    from mindgrasp_launch import launch_api

    if launch_api.using_real_launch():
        return launch_api.DeclareLaunchArgument(name, default_value=default_value,
                                                description=description)
    return CheckedLaunchArgument(name, check=check, default_value=default_value,
                                 description=description)


class PinCheckArgument(DeclareLaunchArgument):
    """``eeg_unpinned:=true|false``, declared after ``eeg_source_id`` and ``eeg_host``: false
    (the default) refuses the launch unless both are given, in one line naming the fix."""

    def execute(self, context: Any) -> None:
        super().execute(context)
        if context.launch_configurations[self.name].strip().lower() == 'true':
            return
        missing = [name for name in ('eeg_source_id', 'eeg_host')
                   if not context.launch_configurations.get(name, '').strip()]
        if missing:
            stream = context.launch_configurations.get('eeg_stream', '')
            msg = (f"the EEG stream {stream!r} is not pinned ({' and '.join(missing)} not "
                   'given): any LSL sender of that name on the network would drive the arm. '
                   'Give eeg_source_id:=<source_id> eeg_host:=<host> (`mindgrasp launch eeg '
                   'eeg_stream:=NAME` logs both on connecting), or eeg_unpinned:=true for a '
                   'bench test.')
            raise LaunchError(msg)


def pin_check_argument(name: str, *, default_value: str, description: str) -> Any:
    """Declare ``name`` as the pinning check of :class:`PinCheckArgument` (a plain argument
    under ``ros2 launch``, where the acquisition node refuses an unpinned stream itself)."""
    from mindgrasp_launch import launch_api

    if launch_api.using_real_launch():
        return launch_api.DeclareLaunchArgument(name, default_value=default_value,
                                                description=description,
                                                choices=['true', 'false'])
    return PinCheckArgument(name, default_value=default_value, description=description,
                            choices=['true', 'false'])
