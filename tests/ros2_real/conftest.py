"""The ``ros2_real`` suite: a real ROS 2 Jazzy (rclpy, rmw_cyclonedds_cpp, the ``ros2`` CLI) on
the other side of our runtime.

The ROS 2 used is the one sourced (``ROS_DISTRO=jazzy``, ``ros2`` on PATH) or the one
``scripts/build_ros2.sh`` built into its cache; without either the suite is skipped with that
command as the reason (the build takes 7-20 min on 2 cores, once per machine).
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import subprocess
import sysconfig
from collections.abc import Callable
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / 'src'
CACHE = Path(os.environ.get('MINDGRASP_ROS2_CACHE', '')
             or Path(os.environ.get('XDG_CACHE_HOME', Path.home() / '.cache'))
             / 'mindgrasp' / 'ros2-jazzy')


def _sourced_env(env_sh: Path, env: dict[str, str] | None = None) -> dict[str, str]:
    """The environment after sourcing ``env_sh`` in bash, from ``env`` (default: a bare one)."""
    out = subprocess.run(['bash', '-c', f'set +u; . "{env_sh}" && env -0'], capture_output=True,
                         check=True, env=env or {'HOME': str(Path.home()), 'PATH': os.defpath})
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


def _workspace_key(ros2_env: dict[str, str], packages: list[Path]) -> str:
    """What a ``colcon build --symlink-install`` of ``packages`` depends on: the ROS 2 it builds
    against, this clone's path (the install links into it), each package's build files and
    interface files, and the names of its files (setup.py installs the data files one by one;
    the Python modules are linked as a folder, so a change of their code needs no rebuild), and
    the names of the files of the top-level config/ (installed as mindgrasp_bringup's)."""
    digest = hashlib.sha256(f'{REPO}\0{ros2_env.get("AMENT_PREFIX_PATH", "")}'.encode())
    for package in packages:
        for path in sorted(p for p in package.rglob('*') if p.is_file()
                           and '__pycache__' not in p.parts and '.egg-info' not in str(p)):
            digest.update(str(path.relative_to(SRC)).encode() + b'\0')
            if path.name in ('package.xml', 'setup.py', 'setup.cfg', 'CMakeLists.txt') or \
                    path.suffix in ('.msg', '.srv'):
                digest.update(path.read_bytes())
    # the top-level config/, which mindgrasp_bringup's setup.py installs file by file
    for path in sorted(p for p in (REPO / 'config').rglob('*') if p.is_file()):
        digest.update(str(path.relative_to(REPO)).encode() + b'\0')
    return digest.hexdigest()[:16]


def _has_our_msgs(ros2_env: dict[str, str]) -> bool:
    """True when the sourced ROS 2 already has our mindgrasp_msgs (the same .msg/.srv files, as
    scripts/build_ros2.sh builds them): the workspace then skips it (about 75 s of rosidl)."""
    ours = {p.relative_to(SRC / 'mindgrasp_msgs'): p.read_bytes()
            for p in (SRC / 'mindgrasp_msgs').rglob('*.[ms][sr][gv]')}
    for prefix in ros2_env.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
        share = Path(prefix) / 'share' / 'mindgrasp_msgs'
        if share.is_dir():
            theirs = {p.relative_to(share): p.read_bytes()
                      for p in share.glob('[ms][sr][gv]/*.[ms][sr][gv]')}
            return theirs == ours
    return False


@pytest.fixture(scope='session')
def colcon_ws(ros2_env) -> dict[str, str]:
    """A colcon workspace of our packages (``src/mindgrasp_*``) built with ``colcon build
    --symlink-install`` against the real ROS 2, cached beside it (``ws-<key>/``, rebuilt when
    :func:`_workspace_key` changes; 40 s for the Python packages, 75 s more when mindgrasp_msgs
    is not built yet), and the environment with it sourced on top: its ``ros2 launch`` finds our
    packages, and our Python dependencies come from this test's virtualenv, appended to
    PYTHONPATH (its own mindgrasp packages are installed editable through .pth files, which
    PYTHONPATH does not read, so the workspace's packages are the ones imported)."""
    packages = sorted(p for p in SRC.glob('mindgrasp_*') if (p / 'package.xml').is_file())
    skip_msgs = _has_our_msgs(ros2_env)
    key = _workspace_key(ros2_env, packages) + ('-overlay' if skip_msgs else '')
    base = Path(ros2_env.get('MINDGRASP_ROS2_CACHE') or CACHE)
    ws = base / f'ws-{key}'
    base.mkdir(parents=True, exist_ok=True)
    with open(base / f'ws-{key}.lock', 'w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)       # one build at a time; the others reuse it
        if not (ws / '.built').is_file():
            shutil.rmtree(ws, ignore_errors=True)
            ws.mkdir(parents=True)
            build = subprocess.run(
                ['colcon', 'build', '--symlink-install', '--base-paths', str(SRC),
                 '--event-handlers', 'console_direct-', *(['--packages-skip', 'mindgrasp_msgs']
                                                          if skip_msgs else [])],
                cwd=ws, env={**ros2_env, 'MAKEFLAGS': '-j2'}, capture_output=True, text=True,
                timeout=900, check=False)
            assert build.returncode == 0, build.stdout[-3000:] + build.stderr[-3000:]
            (ws / '.built').touch()
    env = _sourced_env(ws / 'install' / 'setup.bash', ros2_env)
    venv_paths = dict.fromkeys((sysconfig.get_paths()['purelib'], sysconfig.get_paths()['platlib']))
    env['PYTHONPATH'] = os.pathsep.join([env.get('PYTHONPATH', ''), *venv_paths]).lstrip(os.pathsep)
    env['MINDGRASP_RMW'] = 'rclpy'
    return env


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line('markers', 'ros2_real: needs a real ROS 2 Jazzy '
                                       '(scripts/build_ros2.sh; skipped without one)')
