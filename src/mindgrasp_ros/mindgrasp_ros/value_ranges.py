"""Does a value fit a ROS 2 field type? One check for values a user types (``topic pub``,
``param set``), naming the field, its type and its range.

Message classes convert numeric sequences to numpy and store scalars as given (they are built
hundreds of times per simulated second, so they do not check); an out-of-range scalar such as
``class_index: 300`` for a ``uint8`` only failed in the CDR serialiser as ``struct.error``. Values
from a command line go through :func:`check_value` first::

    check_value("field 'class_index'", 'uint8', 300)
    # ValueError: field 'class_index' is uint8 (a whole number from 0 to 255); 300 is out of range.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ['FLOAT32_MAX', 'INTEGER_RANGES', 'check_value']

#: inclusive range of each ROS 2 integer type (``byte`` and ``char`` are 8-bit unsigned on the
#: wire, as rosidl serialises them)
INTEGER_RANGES: dict[str, tuple[int, int]] = {
    **{f'int{n}': (-(2 ** (n - 1)), 2 ** (n - 1) - 1) for n in (8, 16, 32, 64)},
    **{f'uint{n}': (0, 2 ** n - 1) for n in (8, 16, 32, 64)},
    'byte': (0, 255), 'char': (0, 255), 'octet': (0, 255),
}
#: largest finite float32
FLOAT32_MAX = float(np.finfo(np.float32).max)

_SEQUENCE = re.compile(r'sequence<(?P<inner>[^,>]+)(?:,\s*(?P<bound>\d+))?>')
_ARRAY = re.compile(r'(?P<inner>.+)\[(?P<count>\d+)\]')


def check_value(what: str, ros_type: str, value: Any) -> None:
    """Raise ``ValueError`` unless ``value`` fits ``ros_type``.

    Parameters
    ----------
    what : str
        How the message names the value, e.g. ``"field 'class_index'"``.
    ros_type : str
        A type as ``get_fields_and_field_types()`` gives it: ``'uint8'``, ``'float32'``,
        ``'string<=10'``, ``'sequence<float32>'``, ``'int32[3]'``; a message type
        (``'std_msgs/Header'``) is not checked here (its fields are, one by one).
    value : Any
        The value as YAML gave it (int, float, bool, str or a list of them).
    """
    match = _SEQUENCE.fullmatch(ros_type) or _ARRAY.fullmatch(ros_type)
    if match is not None:
        _check_sequence(what, ros_type, match, value)
        return
    base, _, bound = ros_type.partition('<=')
    if base in INTEGER_RANGES:
        low, high = INTEGER_RANGES[base]
        expected = f'{base} (a whole number from {low} to {high})'
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
            _refuse(what, expected, f'{value!r} is not a whole number')
        if not low <= int(value) <= high:
            _refuse(what, expected, f'{value} is out of range')
    elif base in ('float32', 'float64', 'double', 'float'):
        limit = FLOAT32_MAX if base == 'float32' else math.inf
        expected = base + (f' (a number from {-limit:g} to {limit:g})' if base == 'float32'
                           else ' (a number)')
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
            _refuse(what, expected, f'{value!r} is not a number')
        if math.isfinite(float(value)) and abs(float(value)) > limit:
            _refuse(what, expected, f'{value:g} is out of range')
    elif base in ('bool', 'boolean'):
        if not isinstance(value, (bool, np.bool_)):
            _refuse(what, 'bool (true or false)', f'{value!r} is not one')
    elif base in ('string', 'wstring'):
        if not isinstance(value, str):
            _refuse(what, base, f'{value!r} is not text (quote it: "\'{value}\'")')
        if bound and len(value) > int(bound):
            _refuse(what, ros_type, f'the text has {len(value)} characters')


def _check_sequence(what: str, ros_type: str, match: re.Match, value: Any) -> None:
    if isinstance(value, (str, bytes)) or not isinstance(value, (Sequence, np.ndarray)):
        msg = f'{what} is {ros_type}: give a list, e.g. [1, 2]; {value!r} is not one.'
        raise ValueError(msg)
    groups = match.groupdict()
    if groups.get('count') and len(value) != int(groups['count']):
        msg = f'{what} is {ros_type}: exactly {groups["count"]} values, not {len(value)}.'
        raise ValueError(msg)
    if groups.get('bound') and len(value) > int(groups['bound']):
        msg = f'{what} is {ros_type}: at most {groups["bound"]} values, not {len(value)}.'
        raise ValueError(msg)
    for i, item in enumerate(value):
        check_value(f'{what}[{i}]', groups['inner'].strip(), item)


def _refuse(what: str, expected: str, problem: str) -> None:
    msg = f'{what} is {expected}; {problem}.'
    raise ValueError(msg)
