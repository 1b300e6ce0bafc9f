"""The ``ros2_real`` suite: a real ROS 2 Jazzy (rclpy, rmw_cyclonedds_cpp, the ``ros2`` CLI) on
the other side of our runtime.

The ROS 2 used is the one sourced (``ROS_DISTRO=jazzy``, ``ros2`` on PATH) or the one
``scripts/build_ros2.sh`` built into its cache; without either the suite is skipped with that
command as the reason (the build takes 7-20 min on 2 cores, once per machine).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CACHE = Path(os.environ.get('MINDGRASP_ROS2_CACHE', '')
             or Path(os.environ.get('XDG_CACHE_HOME', Path.home() / '.cache'))
             / 'mindgrasp' / 'ros2-jazzy')


def _sourced_env(env_sh: Path) -> dict[str, str]:
    out = subprocess.run(['bash', '-c', f'. "{env_sh}" && env -0'], capture_output=True,
                         check=True, env={'HOME': str(Path.home()), 'PATH': os.defpath})
    pairs = (item.split('=', 1) for item in out.stdout.decode().split('\0') if '=' in item)
    return dict(pairs)


@pytest.fixture(scope='session')
def ros2_env() -> dict[str, str]:
    """The environment of a real ROS 2 (its PATH, PYTHONPATH, AMENT_PREFIX_PATH ...), with this
    test's ROS_DOMAIN_ID and discovery range."""
    if os.environ.get('ROS_DISTRO') == 'jazzy' and shutil.which('ros2'):
        env = dict(os.environ)
    else:
        found = sorted(CACHE.glob('*/env.sh'), key=lambda p: p.stat().st_mtime)
        if not found:
            pytest.skip('no real ROS 2: run scripts/build_ros2.sh once (7-20 min on 2 cores), '
                        'or source a ROS 2 Jazzy installation')
        env = _sourced_env(found[-1])
    for key in ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE', 'HOME'):
        if key in os.environ:
            env[key] = os.environ[key]
    env['RMW_IMPLEMENTATION'] = 'rmw_cyclonedds_cpp'
    env['PYTHONUNBUFFERED'] = '1'
    return env


@pytest.fixture
def ros2(ros2_env) -> Callable[..., subprocess.CompletedProcess]:
    """``ros2(*args)``: the real ``ros2`` command (no daemon: nothing outlives the test)."""
    def run(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
        return subprocess.run(['ros2', *args], env=ros2_env, capture_output=True, text=True,
                              timeout=timeout, check=False)
    return run


@pytest.fixture
def rclpy_env(ros2_env) -> dict[str, str]:
    """Our environment plus the real rclpy (its Python path and libraries) and
    ``MINDGRASP_RMW=rclpy``: our nodes and tools run on it."""
    env = dict(os.environ)
    for key in ('PYTHONPATH', 'LD_LIBRARY_PATH', 'AMENT_PREFIX_PATH', 'RMW_IMPLEMENTATION'):
        if ros2_env.get(key):
            env[key] = ros2_env[key]
    env['MINDGRASP_RMW'] = 'rclpy'
    return env


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line('markers', 'ros2_real: needs a real ROS 2 Jazzy '
                                       '(scripts/build_ros2.sh; skipped without one)')
