"""``rclpy.parameter.Parameter`` and conversions to/from rcl_interfaces messages."""

from __future__ import annotations

import enum
from typing import Any

import numpy as np

from mindgrasp_ros.typesupport import get_message_class

__all__ = ['Parameter', 'parameter_value_to_python']


def _msg(name: str) -> type:
    return get_message_class(f'rcl_interfaces/msg/{name}')


class Parameter:
    """A named, typed parameter value."""

    class Type(enum.IntEnum):
        NOT_SET = 0
        BOOL = 1
        INTEGER = 2
        DOUBLE = 3
        STRING = 4
        BYTE_ARRAY = 5
        BOOL_ARRAY = 6
        INTEGER_ARRAY = 7
        DOUBLE_ARRAY = 8
        STRING_ARRAY = 9

        @classmethod
        def from_parameter_value(cls, value: Any) -> Parameter.Type:
            """Infer the type of a Python value, as rclpy does."""
            if value is None:
                return cls.NOT_SET
            if isinstance(value, (bool, np.bool_)):
                return cls.BOOL
            if isinstance(value, (int, np.integer)):
                return cls.INTEGER
            if isinstance(value, (float, np.floating)):
                return cls.DOUBLE
            if isinstance(value, str):
                return cls.STRING
            if isinstance(value, (bytes, bytearray)):
                return cls.BYTE_ARRAY
            if isinstance(value, (list, tuple, np.ndarray)):
                items = list(value)
                if not items:
                    return cls.STRING_ARRAY  # rclpy cannot tell either; empty list of strings
                if all(isinstance(v, (bool, np.bool_)) for v in items):
                    return cls.BOOL_ARRAY
                if all(isinstance(v, (int, np.integer)) and not isinstance(v, bool)
                       for v in items):
                    return cls.INTEGER_ARRAY
                if all(isinstance(v, (int, float, np.integer, np.floating))
                       and not isinstance(v, bool) for v in items):
                    return cls.DOUBLE_ARRAY
                if all(isinstance(v, str) for v in items):
                    return cls.STRING_ARRAY
                msg = f'A parameter list must hold one type (bool, int, float or str): {value!r}.'
                raise TypeError(msg)
            msg = f'{type(value).__name__} is not a ROS parameter type: {value!r}.'
            raise TypeError(msg)

        def check(self, value: Any) -> bool:
            if self == Parameter.Type.NOT_SET:
                return value is None
            try:
                inferred = Parameter.Type.from_parameter_value(value)
            except TypeError:
                return False
            if inferred == self:
                return True
            # empty lists fit every array type; ints fit float arrays
            if isinstance(value, (list, tuple)) and not value and self.name.endswith('ARRAY'):
                return True
            return self == Parameter.Type.DOUBLE_ARRAY and inferred == Parameter.Type.INTEGER_ARRAY

    def __init__(self, name: str, type_: Parameter.Type | None = None,
                 value: Any = None) -> None:
        if type_ is None:
            type_ = Parameter.Type.from_parameter_value(value)
        type_ = Parameter.Type(type_)
        if not type_.check(value):
            msg = f"Parameter '{name}': value {value!r} is not of type {type_.name}."
            raise TypeError(msg)
        if type_ == Parameter.Type.DOUBLE and isinstance(value, (int, np.integer)):
            value = float(value)
        if type_ == Parameter.Type.DOUBLE_ARRAY and value is not None:
            value = [float(v) for v in value]
        elif type_.name.endswith('_ARRAY') and value is not None and type_ != type_.BYTE_ARRAY:
            value = list(value)
        self._name = name
        self._type = type_
        self._value = value

    @property
    def name(self) -> str:
        return self._name

    @property
    def type_(self) -> Parameter.Type:
        return self._type

    @property
    def value(self) -> Any:
        return self._value

    def get_parameter_value(self):
        pv = _msg('ParameterValue')(type=int(self._type))
        t = Parameter.Type
        v = self._value
        if self._type == t.BOOL:
            pv.bool_value = bool(v)
        elif self._type == t.INTEGER:
            pv.integer_value = int(v)
        elif self._type == t.DOUBLE:
            pv.double_value = float(v)
        elif self._type == t.STRING:
            pv.string_value = v
        elif self._type == t.BYTE_ARRAY:
            pv.byte_array = bytes(v)
        elif self._type == t.BOOL_ARRAY:
            pv.bool_array_value = np.asarray(v, dtype=bool)
        elif self._type == t.INTEGER_ARRAY:
            pv.integer_array_value = np.asarray(v, dtype=np.int64)
        elif self._type == t.DOUBLE_ARRAY:
            pv.double_array_value = np.asarray(v, dtype=np.float64)
        elif self._type == t.STRING_ARRAY:
            pv.string_array_value = list(v)
        return pv

    def to_parameter_msg(self):
        return _msg('Parameter')(name=self._name, value=self.get_parameter_value())

    @classmethod
    def from_parameter_msg(cls, msg) -> Parameter:
        return cls(msg.name, Parameter.Type(msg.value.type),
                   parameter_value_to_python(msg.value))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Parameter):
            return NotImplemented
        return (self._name, self._type, self._value) == (other._name, other._type, other._value)

    def __repr__(self) -> str:
        return f'Parameter({self._name!r}, {self._type.name}, {self._value!r})'


def parameter_value_to_python(pv) -> Any:
    """Python value of an rcl_interfaces/ParameterValue."""
    t = Parameter.Type(pv.type)
    if t == t.NOT_SET:
        return None
    if t == t.BOOL:
        return bool(pv.bool_value)
    if t == t.INTEGER:
        return int(pv.integer_value)
    if t == t.DOUBLE:
        return float(pv.double_value)
    if t == t.STRING:
        return str(pv.string_value)
    if t == t.BYTE_ARRAY:
        return bytes(np.asarray(pv.byte_array, dtype=np.uint8))
    if t == t.BOOL_ARRAY:
        return [bool(v) for v in pv.bool_array_value]
    if t == t.INTEGER_ARRAY:
        return [int(v) for v in pv.integer_array_value]
    if t == t.DOUBLE_ARRAY:
        return [float(v) for v in pv.double_array_value]
    return list(pv.string_array_value)
