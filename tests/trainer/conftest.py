"""Fixtures of the trainer tests: a ROS context in the test process for the whole module.

Node processes come from the shared ``spawn_node`` fixture (tests/conftest.py); parameters go as
keywords: ``spawn_node('mindgrasp_trainer.graz_node', n_trials=4, seed=3)``."""

from __future__ import annotations

from collections.abc import Callable, Iterator

import pytest

from mindgrasp_testing import spin_until as _spin_until


@pytest.fixture(scope='module')
def ros() -> Iterator[object]:
    """The rclpy module, initialised for the test module. Our client layer is never optional: an
    error here fails the tests instead of skipping them."""
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    try:
        yield rclpy
    finally:
        rclpy.try_shutdown()


@pytest.fixture
def spin_until(ros) -> Callable[..., bool]:
    """``spin_until(node, condition, timeout)``: spin until ``condition()`` holds or ``timeout`` s
    pass; returns the condition."""
    return lambda node, condition, timeout: _spin_until(node, condition, timeout)


@pytest.fixture
def make_node(ros) -> Iterator[Callable[[str], object]]:
    """``make_node(name)``: a node in the test process, destroyed at teardown even when the test
    fails (a leftover node, say a stand-in's /sim/reset service, would answer the next test)."""
    nodes = []

    def make(name: str) -> object:
        nodes.append(ros.node.Node(name))
        return nodes[-1]

    yield make
    for node in nodes:
        node.destroy_node()
