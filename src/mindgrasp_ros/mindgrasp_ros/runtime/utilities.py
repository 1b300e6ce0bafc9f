"""``rclpy.utilities``: the process's default context, ``ok`` and ``remove_ros_args``."""

from __future__ import annotations

from mindgrasp_ros.runtime.arguments import remove_ros_args
from mindgrasp_ros.runtime.context import Context

__all__ = ['get_default_context', 'ok', 'remove_ros_args']

_default_context = Context()


def get_default_context() -> Context:
    """The context of nodes and executors constructed without a ``context`` argument."""
    return _default_context


def ok(*, context: Context | None = None) -> bool:
    """Whether ``context`` (default: the default context) is initialised and not shut down."""
    return (context or _default_context).ok()
