"""Shared pytest fixtures: DDS isolation, an initialised rclpy context, node processes.

Helpers (``spin_until``, ``NodeProcess``) are in ``mindgrasp_testing``."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from mindgrasp_testing import NodeProcess

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO.parent / 'shared' / 'data'

# DDS stays on this host and on a domain of its own: each pytest process (the xdist workers
# gw0, gw1, ...) claims a domain no other test process on this host holds, so suites run side
# by side never cross-talk (a sim of one suite answering another's test).
os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
_DOMAIN_LOCK = None


def _claim_domain() -> int:
    """A ROS domain id held by an exclusive lock on ``<tmp>/mindgrasp-test-domain-<id>.lock``
    for the life of this process (the OS drops the lock when it ends, however it ends)."""
    global _DOMAIN_LOCK
    import fcntl
    import tempfile

    for i in range(231):
        domain = 1 + (os.getpid() + i) % 231
        path = Path(tempfile.gettempdir()) / f'mindgrasp-test-domain-{domain}.lock'
        lock = path.open('w')  # held open, not closed on return: it keeps the claim
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        _DOMAIN_LOCK = lock
        return domain
    raise RuntimeError('All 231 ROS domain ids are held by test processes on this host.')


if 'ROS_DOMAIN_ID' not in os.environ or os.environ.get('PYTEST_XDIST_WORKER'):
    os.environ['ROS_DOMAIN_ID'] = str(_claim_domain())
if SHARED_DATA.is_dir():
    os.environ.setdefault('MNE_DATASETS_EEGBCI_PATH', str(SHARED_DATA))


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    """A test marked ``exclusive`` (a live real-time run whose outcome is its point) runs while
    no other test of this suite runs: around each test's whole protocol (its fixtures of any
    scope set up, run and torn down) it takes an exclusive lock on a file of this suite run
    (shared by the xdist workers), every other test a shared one. Outermost (tryfirst), so the
    wait for the other worker's current test is not counted in any test's timeout."""
    import fcntl
    import tempfile

    run = os.environ.get('PYTEST_XDIST_TESTRUNUID') or f'pid{os.getpid()}'
    path = Path(tempfile.gettempdir()) / f'mindgrasp-exclusive-{run}.lock'
    exclusive = item.get_closest_marker('exclusive') is not None
    with path.open('a') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


@pytest.fixture(autouse=True)
def _process_log_level() -> Iterator[None]:
    """Each test starts at the process's default log level and leaves it there: a lock-step run
    sets the level of every node logger in its process (``set_log_level``, as ``--log-level``),
    and a later test in the same xdist worker that expects an info line would otherwise depend on
    which tests ran before it."""
    from mindgrasp_ros.runtime.logging import get_logger_effective_level, set_logger_level

    level = get_logger_effective_level('')
    yield
    set_logger_level('', level)


@pytest.fixture
def rclpy_ctx() -> Iterator[object]:
    """``rclpy`` (ours or the real one), initialised for the test and shut down after it."""
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    try:
        yield rclpy
    finally:
        rclpy.try_shutdown()


def ros_args(args: tuple[str, ...], params: dict[str, object]) -> list[str]:
    """``args`` followed by ``-p name:=value`` for each of ``params`` (in ``--ros-args``)."""
    out = list(args)
    if params and '--ros-args' not in out:
        out.append('--ros-args')
    for name, value in params.items():
        text = str(value).lower() if isinstance(value, bool) else str(value)
        out += ['-p', f'{name}:={text}']
    return out


@pytest.fixture
def spawn_node(tmp_path: Path) -> Iterator[Callable[..., NodeProcess]]:
    """Factory: ``spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'x:=1')``, or with the
    parameters as keywords: ``spawn_node('mindgrasp_sim.sim_node', x=1, gui=False)``.

    Processes inherit the test's ROS_DOMAIN_ID and are stopped at teardown; their output is in
    ``proc.output()`` (and printed when a test fails)."""
    procs: list[NodeProcess] = []

    def start(module: str, *args: str, env: dict[str, str] | None = None,
              **params: object) -> NodeProcess:
        """``module`` is a module name (run with -m) or a path to a .py script; ``params`` become
        ``-p name:=value`` after ``--ros-args`` (booleans as ``true``/``false``)."""
        args = ros_args(args, params)
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
