"""Trials spread over worker processes or a Ray cluster; the records do not depend on where.

Each trial runs in its own fresh lock-step graph (:func:`~mindgrasp_experiments.engine.run_trial`)
seeded from ``(seed, trial)``, so a trial's record is the same whichever process runs it. With
``workers > 1`` trials are handed out one at a time to ``workers`` spawned processes (each builds
the node graph's imports once). With ``ray`` (``auto``: a new local Ray instance of this
process; ``HOST:PORT`` or ``ray://HOST:PORT``: a cluster) every trial is a Ray task
(optional extra ``cluster``); the driver gathers the records as they finish.
"""

from __future__ import annotations

import atexit
import concurrent.futures
import multiprocessing
import socket
from collections.abc import Iterator, Sequence

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.engine import TrialRun, run_trial
from mindgrasp_ros.graph.spec import NodeSpec

__all__ = ['check_ray_address', 'run_trials']

#: how long to wait for a Ray address to answer before saying it cannot be reached (s)
RAY_CONNECT_TIMEOUT = 5.0


def _worker_init() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the parent's to handle


def check_ray_address(address: str) -> None:
    """Raise :class:`ExperimentError` (one sentence with the fix) unless Ray is installed and
    ``address`` (``auto``, ``HOST:PORT`` or ``ray://HOST:PORT``) answers on TCP."""
    try:
        import ray  # noqa: F401
    except ImportError:
        msg = ('--ray needs Ray, the optional extra: pip install -c constraints.txt -e '
               '".[cluster]"')
        raise ExperimentError(msg) from None
    if address == 'auto':
        return
    host, _, port = address.removeprefix('ray://').rpartition(':')
    if not host or not port.isdigit():
        msg = (f'--ray {address!r} is not a Ray address; give auto (a local instance), '
               f'HOST:PORT of the head node (ray start --head) or ray://HOST:PORT (Ray client).')
        raise ExperimentError(msg)
    try:
        socket.create_connection((host, int(port)), timeout=RAY_CONNECT_TIMEOUT).close()
    except OSError as exc:
        msg = (f'--ray {address}: the Ray cluster cannot be reached ({exc}); start its head '
               f'node with "ray start --head" there, or check the address and firewall.')
        raise ExperimentError(msg) from None


def _ray_trials(components: Sequence[NodeSpec], trials: Sequence[int], *, seed: int,
                address: str, step_s: float, log_level: str) -> Iterator[TrialRun]:
    import ray

    check_ray_address(address)
    if not ray.is_initialized():
        # the workers import this package from the driver's environment; Ray stays up for the
        # next batch (a sweep's next point) and ends with this process
        options = {'include_dashboard': False, 'log_to_driver': False,
                   'configure_logging': False}
        if address != 'auto':
            ray.init(address=address, **options)
        else:
            # a Ray instance of our own on this machine (address 'local'), on loopback; joining
            # whatever instance runs here could hand our trials to another user's workers
            ray.init(address='local', _node_ip_address='127.0.0.1', **options)
        atexit.register(ray.shutdown)
    task = ray.remote(run_trial).options(num_cpus=1, max_retries=0)
    pending = [task.remote(list(components), trial, seed=seed, step_s=step_s,
                           log_level=log_level) for trial in trials]
    finished = False
    try:
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            yield ray.get(ready[0])
        finished = True
    finally:
        if not finished:
            for ref in pending:          # Ctrl-C (or an error): stop what still runs
                ray.cancel(ref, force=True)


def run_trials(components: Sequence[NodeSpec], trials: Sequence[int], *, seed: int,
               workers: int = 1, step_s: float = 0.02, log_level: str = 'warn',
               ray: str | None = None) -> Iterator[TrialRun]:
    """Run ``trials`` (numbers) and yield each :class:`TrialRun` as it finishes (``workers``
    processes; 1 runs them here, in order; ``ray``: as Ray tasks, see the module docstring)."""
    if ray is not None:
        yield from _ray_trials(components, trials, seed=seed, address=ray, step_s=step_s,
                               log_level=log_level)
        return
    if workers <= 1:
        for trial in trials:
            yield run_trial(components, trial, seed=seed, step_s=step_s, log_level=log_level)
        return
    ctx = multiprocessing.get_context('spawn')
    pool = concurrent.futures.ProcessPoolExecutor(max_workers=workers, mp_context=ctx,
                                                  initializer=_worker_init)
    futures = [pool.submit(run_trial, list(components), trial, seed=seed, step_s=step_s,
                           log_level=log_level) for trial in trials]
    finished = False
    try:
        for future in concurrent.futures.as_completed(futures):
            yield future.result()
        finished = True
    finally:
        if finished:
            pool.shutdown(wait=True)
        else:
            # Ctrl-C (or an error): the trials still running are abandoned; stop our workers
            processes = list((getattr(pool, '_processes', None) or {}).values())
            pool.shutdown(wait=False, cancel_futures=True)
            for process in processes:
                if process.is_alive():
                    process.terminate()
