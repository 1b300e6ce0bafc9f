"""Small helpers between bag QoS dicts / type names and the ROS client layer (rclpy API)."""

from __future__ import annotations

import importlib
import json
from typing import Any

__all__ = ['message_class', 'param_args', 'qos_profile']


def message_class(type_name: str) -> Any:
    """The message class of ``'pkg/msg/Type'`` from ``mindgrasp_ros.interfaces``.

    Raises
    ------
    ImportError, AttributeError
        The client layer does not know the type.
    """
    package, kind, name = type_name.split('/')
    module = importlib.import_module(f'mindgrasp_ros.interfaces.{package}.{kind}')
    return getattr(module, name)


def qos_profile(rclpy: Any, qos: dict[str, Any]) -> Any:
    """An rclpy ``QoSProfile`` from ``{'reliability', 'durability', 'depth'}`` (bag QoS names)."""
    q = rclpy.qos
    return q.QoSProfile(
        depth=int(qos.get('depth') or 10),
        history=q.HistoryPolicy.KEEP_LAST,
        reliability=(q.ReliabilityPolicy.RELIABLE if qos.get('reliability') == 'reliable'
                     else q.ReliabilityPolicy.BEST_EFFORT),
        durability=(q.DurabilityPolicy.TRANSIENT_LOCAL
                    if qos.get('durability') == 'transient_local'
                    else q.DurabilityPolicy.VOLATILE))


def param_args(params: dict[str, Any]) -> list[str]:
    """``['--ros-args', '-p', 'name:=value', ...]`` with values written as YAML.

    Strings are JSON-quoted (valid YAML) so a regex such as ``[a-z]+`` stays a string; floats keep
    a decimal point so they stay doubles.
    """
    out = ['--ros-args']
    for name, value in params.items():
        if isinstance(value, bool):
            text = 'true' if value else 'false'
        elif isinstance(value, float):
            text = repr(value)
        elif isinstance(value, int):
            text = str(value)
        else:
            text = json.dumps(value)
        out += ['-p', f'{name}:={text}']
    return out
