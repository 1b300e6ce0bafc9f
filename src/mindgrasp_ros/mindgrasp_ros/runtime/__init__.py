"""The rclpy-compatible runtime of MIndGrasp-ROS (selected when the real rclpy is not).

Module-level functions mirror ``rclpy``: :func:`init`, :func:`shutdown`, :func:`ok`,
:func:`spin`, :func:`spin_once`, :func:`spin_until_future_complete`, :func:`create_node`; the
submodules mirror ``rclpy.node``, ``rclpy.qos``, ``rclpy.executors``, ``rclpy.parameter``,
``rclpy.time``, ``rclpy.duration``, ``rclpy.clock``, ``rclpy.task``, ``rclpy.logging``.
"""

from __future__ import annotations

import threading
from typing import Any

from mindgrasp_ros.process import handle_stop_signals
from mindgrasp_ros.runtime import (
    callback_groups,
    clock,
    duration,
    exceptions,
    logging,
    parameter,
    qos,
    task,
    time,
    utilities,
)
from mindgrasp_ros.runtime.context import Context
from mindgrasp_ros.runtime.utilities import get_default_context, ok

__all__ = [
    'callback_groups', 'clock', 'create_node', 'duration', 'exceptions',
    'executors', 'get_default_context', 'init', 'logging', 'node', 'ok', 'parameter', 'qos',
    'shutdown', 'spin', 'spin_once', 'spin_until_future_complete', 'task', 'time',
    'try_shutdown', 'utilities',
]

_global_executor: Any = None
_executor_lock = threading.Lock()


def init(*, args: list[str] | None = None, context: Context | None = None,
         domain_id: int | None = None, signal_handler_options: object = None) -> None:
    """Initialise the context: parse ``--ros-args`` of ``args`` (default ``sys.argv``) and join
    the DDS domain (``ROS_DOMAIN_ID`` unless ``domain_id`` is given)."""
    ctx = context or get_default_context()
    ctx.init(args, domain_id=domain_id)
    handle_stop_signals()      # as rclpy: whatever the process inherited


def shutdown(*, context: Context | None = None, uninstall_handlers: bool | None = None) -> None:
    global _global_executor
    ctx = context or get_default_context()
    if ctx is get_default_context():
        with _executor_lock:
            if _global_executor is not None:
                _global_executor.shutdown()
                _global_executor = None
    ctx.shutdown()


def try_shutdown(*, context: Context | None = None) -> None:
    ctx = context or get_default_context()
    if ctx.ok():
        shutdown(context=ctx)


def create_node(node_name: str, **kwargs: Any) -> Any:
    from mindgrasp_ros.runtime.node import Node

    return Node(node_name, **kwargs)


def get_global_executor() -> Any:
    global _global_executor
    from mindgrasp_ros.runtime.executors import SingleThreadedExecutor

    with _executor_lock:
        if _global_executor is None:
            _global_executor = SingleThreadedExecutor()
        return _global_executor


def spin(node: Any, executor: Any = None) -> None:
    """Run the node's callbacks until shutdown (Ctrl-C raises KeyboardInterrupt)."""
    executor = executor or get_global_executor()
    try:
        executor.add_node(node)
        while node.context.ok():
            executor.spin_once()
    finally:
        executor.remove_node(node)


def spin_once(node: Any, *, executor: Any = None, timeout_sec: float | None = None) -> None:
    executor = executor or get_global_executor()
    try:
        executor.add_node(node)
        executor.spin_once(timeout_sec=timeout_sec)
    finally:
        executor.remove_node(node)


def spin_until_future_complete(node: Any, future: Any, executor: Any = None,
                               timeout_sec: float | None = None) -> None:
    executor = executor or get_global_executor()
    try:
        executor.add_node(node)
        executor.spin_until_future_complete(future, timeout_sec)
    finally:
        executor.remove_node(node)


def __getattr__(name: str) -> Any:
    import importlib

    if name in ('node', 'executors', 'rate', 'names', 'arguments', 'publisher', 'subscription',
                'timer', 'service', 'client', 'guard_condition'):
        module = importlib.import_module(f'{__name__}.{name}')
        globals()[name] = module
        return module
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
