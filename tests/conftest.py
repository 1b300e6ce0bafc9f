"""Shared pytest fixtures: DDS isolation, an initialised rclpy context, node processes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / 'shared' / 'data'

# DDS stays on this host and on a domain of its own, so parallel runs never cross-talk.
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
os.environ.setdefault('ROS_DOMAIN_ID', str(100 + os.getpid() % 100))
if SHARED_DATA.is_dir():
    os.environ.setdefault('MNE_DATASETS_EEGBCI_PATH', str(SHARED_DATA))


@pytest.fixture
def rclpy_ctx() -> Iterator[object]:
    """``rclpy`` (ours or the real one), initialised for the test and shut down after it."""
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    try:
        yield rclpy
    finally:
        rclpy.try_shutdown()


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


class NodeProcess:
    """A node started as ``python -m module [args]`` in its own process."""

    def __init__(self, module: str, args: list[str], env: dict[str, str], log: Path) -> None:
        self.module = module
        self.log_path = log
        self._log = log.open('wb')
        target = [module] if module.endswith('.py') else ['-m', module]
        self.proc = subprocess.Popen(
            [sys.executable, '-u', *target, *args], stdout=self._log,
            stderr=subprocess.STDOUT, env=env, start_new_session=True)

    def output(self) -> str:
        if not self._log.closed:
            self._log.flush()
        return self.log_path.read_text(errors='replace')

    def stop(self, timeout: float = 5.0) -> int:
        """SIGINT, then SIGTERM, then SIGKILL; returns the exit code."""
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGKILL):
            if self.proc.poll() is not None:
                break
            self.proc.send_signal(sig)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                continue
        code = self.proc.wait()
        self._log.close()
        return code

    def wait(self, timeout: float) -> int:
        return self.proc.wait(timeout)

    def wait_for_output(self, text: str, timeout: float = 20.0) -> bool:
        """Wait until the process printed ``text`` (e.g. a "ready" line)."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.output():
                return True
            if self.proc.poll() is not None:
                return text in self.output()
            time.sleep(0.05)
        return False


@pytest.fixture
def spawn_node(tmp_path: Path) -> Iterator[Callable[..., NodeProcess]]:
    """Factory: ``spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'x:=1')``.

    Processes inherit the test's ROS_DOMAIN_ID and are stopped at teardown; their output is in
    ``proc.output()`` (and printed when a test fails)."""
    procs: list[NodeProcess] = []

    def start(module: str, *args: str, env: dict[str, str] | None = None) -> NodeProcess:
        """``module`` is a module name (run with -m) or a path to a .py script."""
        full_env = dict(os.environ)
        full_env.update(env or {})
        full_env.setdefault('PYTHONUNBUFFERED', '1')
        proc = NodeProcess(module, list(args), full_env,
                           tmp_path / f'{Path(module).stem.rsplit(".", 1)[-1]}-{len(procs)}.log')
        procs.append(proc)
        return proc

    yield start
    for proc in reversed(procs):
        proc.stop()
        out = proc.output()
        if out:
            print(f'----- output of {proc.module} -----\n{out[-4000:]}')
