"""Fixtures of the trainer tests: a ROS context in the test process and node subprocesses."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable, Iterator

import pytest


def ros_available() -> str:
    """'' when the client layer works here, else why not."""
    try:
        from mindgrasp_ros import rclpy

        rclpy.init()
        rclpy.shutdown()
    except Exception as err:  # any failure means: skip the ROS tests
        return f'the ROS 2 client layer (mindgrasp_ros) does not work yet: {err!r}'
    return ''


@pytest.fixture(scope='module')
def ros():
    """The rclpy module, initialised for the test module; skips when the layer is missing."""
    reason = ros_available()
    if reason:
        pytest.skip(reason)
    from mindgrasp_ros import rclpy

    rclpy.init()
    yield rclpy
    rclpy.shutdown()


@pytest.fixture
def spawn(tmp_path) -> Iterator[Callable[..., subprocess.Popen]]:
    """Start ``python -m module --ros-args -p k:=v ...``; every process is stopped at teardown.

    The output (stdout and stderr) goes to a file, so a chatty node never blocks on a full pipe;
    ``proc.output()`` returns all of it so far.
    """
    procs: list[subprocess.Popen] = []

    def start(module: str, **params: object) -> subprocess.Popen:
        args = [sys.executable, '-m', module, '--ros-args']
        for name, value in params.items():
            if isinstance(value, bool):
                value = str(value).lower()
            args += ['-p', f'{name}:={value}']
        log = tmp_path / f'{module.rsplit(".", 1)[-1]}_{len(procs)}.log'
        with open(log, 'w', encoding='utf-8') as f:
            env = os.environ | {'PYTHONUNBUFFERED': '1'}  # the log is complete at any time
            proc = subprocess.Popen(args, stdout=f, stderr=subprocess.STDOUT, env=env)
        proc.output = lambda: log.read_text(encoding='utf-8', errors='replace')
        procs.append(proc)
        return proc

    yield start
    for proc in procs:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(5)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait(5)


def _spin_until(rclpy, node, condition: Callable[[], bool], timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        rclpy.spin_once(node, timeout_sec=0.01)
    return condition()


@pytest.fixture
def spin_until(ros) -> Callable[..., bool]:
    """``spin_until(node, condition, timeout)``: spin until ``condition()`` holds or ``timeout`` s
    pass; returns the condition."""
    return lambda node, condition, timeout: _spin_until(ros, node, condition, timeout)
