"""A node in a child process of its own, its output in a log file: for tools that start a few
nodes and talk to them over DDS (``evaluate classifier --live``, the tests). Whole node graphs
are the launcher's (``mindgrasp launch``); this is the small case without a launch file."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

from mindgrasp_ros.start import python_module_argv

__all__ = ['NodeProcess']


class NodeProcess:
    """``python -m module [args]`` (or ``python script.py [args]``) in a new session, stdout and
    stderr in ``log``; ``env`` None: this process's environment.

    Stopped as the launcher stops a node: SIGINT, then SIGTERM, then SIGKILL, each given
    ``timeout`` seconds.
    """

    def __init__(self, module: str, args: list[str], env: dict[str, str] | None,
                 log: Path) -> None:
        self.module = module
        self.log_path = log
        self._log = log.open('wb')
        program = [sys.executable, module] if module.endswith('.py') else \
            python_module_argv(module)
        self.proc = subprocess.Popen(
            [program[0], '-u', *program[1:], *args], stdout=self._log,
            stderr=subprocess.STDOUT, env=env, start_new_session=True)

    def output(self) -> str:
        """Everything the process printed so far."""
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
        """The exit code, once the process ended (``subprocess.TimeoutExpired`` after
        ``timeout`` s)."""
        return self.proc.wait(timeout)

    def poll(self) -> int | None:
        """The exit code, or None while the process runs."""
        return self.proc.poll()

    @property
    def pid(self) -> int:
        return self.proc.pid

    def wait_for_output(self, text: str, timeout: float = 20.0) -> bool:
        """Wait until the process printed ``text`` (e.g. a "ready" line); False when it ended or
        ``timeout`` s passed without it."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if text in self.output():
                return True
            if self.proc.poll() is not None:
                return text in self.output()
            time.sleep(0.05)
        return False
