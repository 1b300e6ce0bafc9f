"""Test helpers shared by every test folder (import as ``from mindgrasp_testing import ...``).

A module of its own, because ``from conftest import`` picks whichever conftest.py comes first on
sys.path when several test folders have one.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from mindgrasp_ros.node_process import NodeProcess

__all__ = ['NodeProcess', 'spin_until']


def spin_until(node: object, predicate: Callable[[], bool], timeout: float = 10.0,
               executor: object = None) -> bool:
    """Spin ``node`` until ``predicate()`` is true or ``timeout`` seconds pass."""
    from mindgrasp_ros import rclpy

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        if executor is not None:
            executor.spin_once(timeout_sec=0.05)
        else:
            rclpy.spin_once(node, timeout_sec=0.05)
    return predicate()
