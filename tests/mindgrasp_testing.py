"""Test helpers shared by every test folder (import as ``from mindgrasp_testing import ...``).

A module of its own, because ``from conftest import`` picks whichever conftest.py comes first on
sys.path when several test folders have one.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

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

    def poll(self) -> int | None:
        """The exit code, or None while the process runs."""
        return self.proc.poll()

    @property
    def pid(self) -> int:
        return self.proc.pid

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
