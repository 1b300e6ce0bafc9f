"""Trials spread over worker processes; the records do not depend on how many.

Each trial runs in its own fresh lock-step graph (:func:`~mindgrasp_experiments.engine.run_trial`)
seeded from ``(seed, trial)``, so a trial's record is the same whichever process runs it. With
``workers > 1`` trials are handed out one at a time to ``workers`` spawned processes (each builds
the node graph's imports once) and collected in trial order.
"""

from __future__ import annotations

import concurrent.futures
import multiprocessing
from collections.abc import Iterator, Sequence

from mindgrasp_experiments.engine import LockstepComponent, TrialRun, run_trial

__all__ = ['run_trials']


def _worker_init() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the parent's to handle


def run_trials(components: Sequence[LockstepComponent], trials: Sequence[int], *, seed: int,
               workers: int = 1, step_s: float = 0.02, log_level: str = 'warn',
               ) -> Iterator[TrialRun]:
    """Run ``trials`` (numbers) and yield each :class:`TrialRun` as it finishes (``workers``
    processes; 1 runs them here, in order)."""
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
