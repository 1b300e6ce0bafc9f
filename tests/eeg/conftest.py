"""Fixtures of the EEG tests: unique LSL stream names and real outlets in subprocesses."""

from __future__ import annotations

import os
import subprocess
import sys
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

HERE = Path(__file__).parent
PYTHON = sys.executable


@pytest.fixture
def stream_name() -> str:
    """A stream name no other test or helper uses (LSL streams are host-wide)."""
    return f'mg_test_eeg_{uuid.uuid4().hex[:10]}'


@pytest.fixture
def lsl_source() -> Iterator[Callable[..., subprocess.Popen]]:
    """Start ``tests/eeg/lsl_source.py`` in a subprocess; killed at the end of the test."""
    procs: list[subprocess.Popen] = []

    def start(name: str, *args: str) -> subprocess.Popen:
        proc = subprocess.Popen([PYTHON, str(HERE / 'lsl_source.py'), '--name', name, *args],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        procs.append(proc)
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert line.strip() == 'READY', f'LSL source did not start: {line!r}'
        return proc

    yield start
    for proc in procs:
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=10)


def ros_env() -> dict[str, str]:
    """Environment for node subprocesses: this helper's DDS domain, localhost discovery."""
    env = dict(os.environ)
    env.setdefault('ROS_DOMAIN_ID', '12')
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env['PYTHONUNBUFFERED'] = '1'
    return env
