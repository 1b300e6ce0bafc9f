"""Helpers of the launcher tests: run ``mindgrasp launch`` in a subprocess, as a user would."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BRINGUP_TESTS = HERE.parent


def launch_env(**extra: str) -> dict[str, str]:
    """Environment for a launch: fixtures importable, this test's ROS domain kept, no colour."""
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(
        [str(BRINGUP_TESTS), *filter(None, [env.get('PYTHONPATH', '')])])
    env.setdefault('ROS_DOMAIN_ID', '17')
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env['NO_COLOR'] = '1'
    env.update(extra)
    return env


def launch_cmd(*args: str) -> list[str]:
    """``python -m mindgrasp_cli launch <args>``."""
    return [sys.executable, '-m', 'mindgrasp_cli', 'launch', *args]


def fixture(name: str) -> str:
    """Path of a fixture launch file."""
    return str(HERE / name)


def run_launch(*args: str, timeout: float = 60.0, **env: str) -> subprocess.CompletedProcess:
    """Run a launch to its end; returns the completed process (text stdout/stderr)."""
    return subprocess.run(launch_cmd(*args), env=launch_env(**env), capture_output=True,
                          text=True, timeout=timeout, check=False)


def start_launch(*args: str, **env: str) -> subprocess.Popen:
    """Start a launch in the background (stdout and stderr to pipes)."""
    return subprocess.Popen(launch_cmd(*args), env=launch_env(**env), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def wait_for_file_text(path: Path, text: str, timeout: float = 30.0) -> bool:
    """Wait until ``path`` exists and contains ``text``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.is_file() and text in path.read_text(encoding='utf-8', errors='replace'):
            return True
        time.sleep(0.05)
    return False


def kill_group(proc: subprocess.Popen) -> None:
    """Last-resort cleanup of a launch started by a test."""
    if proc.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
