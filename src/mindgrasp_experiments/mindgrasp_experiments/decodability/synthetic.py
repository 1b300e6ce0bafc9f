"""The virtual subject's decodability: its runs on a cue schedule, and its figures averaged over
sessions.

:func:`synthetic_figures` generates :class:`~mindgrasp_eeg.synthetic.SyntheticEEG` runs that
follow the cue schedules of a template (a replay subject's recordings, so both are measured on
the same protocol, or
:func:`~mindgrasp_experiments.decodability.paradigm.eegmmidb_like_schedules`), one generator and
one seed per run so ``nonstationarity`` changes the conditions between runs, and measures them
as a real subject (:func:`~mindgrasp_experiments.decodability.figures.measure`), averaged over a
few repetitions with other seeds.
"""

from __future__ import annotations

from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from mindgrasp_common.mi import REST
from mindgrasp_common.types import Recording
from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE
from mindgrasp_experiments.decodability.figures import (
    Decodability,
    average,
    measure,
    one_blas_thread,
)
from mindgrasp_experiments.decodability.paradigm import MAX_IMAGERY_S, RunSchedule

__all__ = ['DEFAULT_SETTINGS', 'FIT_START', 'PARAMETER_BOUNDS', 'synthetic_figures',
           'synthetic_runs']

#: the virtual subject's settings that :func:`fit_virtual` searches, and their ranges
PARAMETER_BOUNDS: dict[str, tuple[float, float]] = {
    'separability': (0.0, 2.0),
    'lateral_separability': (0.0, 1.0),
    'rest_separability': (0.0, 2.0),
    'nonstationarity': (0.0, 3.0),
}
_NAMES = tuple(PARAMETER_BOUNDS)
#: the settings of the original virtual subject (SyntheticEEG's defaults)
DEFAULT_SETTINGS: dict[str, float] = {'separability': 1.0, 'lateral_separability': 1.0,
                                      'rest_separability': 0.0, 'nonstationarity': 0.0}
#: where :func:`fit_virtual` starts: a subject with a plain, moderately variable signature
FIT_START: dict[str, float] = {'separability': 1.0, 'lateral_separability': 0.5,
                               'rest_separability': 0.3, 'nonstationarity': 1.0}


def _run_seed(seed: int, repeat: int, run: int) -> int:
    """Seed of one synthetic run: distinct for every (seed, repetition, run)."""
    return int(np.random.SeedSequence([seed, repeat, run]).generate_state(1)[0])


def synthetic_runs(schedules: Sequence[RunSchedule], *, seed: int = 0, repeat: int = 0,
                   first_run: int = 0, head_seed: int = 0, separability: float = 1.0,
                   lateral_separability: float = 1.0, rest_separability: float = 0.0,
                   nonstationarity: float = 0.0, rate: float = NAUTILUS_RATE,
                   run_normals: Sequence[np.ndarray] | None = None) -> list[Recording]:
    """Virtual-subject EEG of ``schedules``, one :class:`SyntheticEEG` (own run seed) per run.

    ``run_normals`` (one array of shape (RunConditions.N_DRAWS,) per schedule) sets each run's
    random conditions instead of its seed (:class:`~mindgrasp_eeg.synthetic.RunConditions`).

    Returns
    -------
    recordings : list of Recording
        32 channels (:data:`NAUTILUS_32`) at ``rate`` Hz, volts; ``events`` as the schedule
        (:data:`REST` for rest).
    """
    from mindgrasp_eeg.synthetic import SyntheticEEG

    out = []
    for i, sched in enumerate(schedules):
        run_seed = _run_seed(seed, repeat, first_run + i)
        gen = SyntheticEEG(NAUTILUS_32, rate, seed=run_seed, head_seed=head_seed,
                           separability=separability, lateral_separability=lateral_separability,
                           rest_separability=rest_separability, nonstationarity=nonstationarity,
                           run_normals=None if run_normals is None else run_normals[i])
        n_total = round(sched.duration * rate)
        bounds = [round(t * rate) for t, _ in sched.cues] + [n_total]
        parts = [gen.generate(bounds[0], None)]
        for (_t, label), k0, k1 in zip(sched.cues, bounds[:-1], bounds[1:], strict=True):
            hold = k1 - k0 if label == REST else min(k1 - k0, round(MAX_IMAGERY_S * rate))
            parts.append(gen.generate(hold, None if label == REST else label))
            parts.append(gen.generate(k1 - k0 - hold, None))
        rows = [(k, label) for (_t, label), k in zip(sched.cues, bounds[:-1], strict=True)]
        events = np.array(rows, dtype=int).reshape(-1, 2)
        out.append(Recording(data=np.vstack(parts), rate=rate, channels=list(NAUTILUS_32),
                             events=events, source=f'virtual subject run seed {run_seed}'))
    return out


@dataclass(frozen=True)
class _Job:
    calibration: tuple[RunSchedule, ...]
    test: tuple[RunSchedule, ...]
    channels: tuple[str, ...]
    params: tuple[float, ...]       # in the order of PARAMETER_BOUNDS
    seed: int
    repeat: int
    head_seed: int
    rate: float
    run_normals: np.ndarray           # (n_runs, RunConditions.N_DRAWS)


def _measure_job(job: _Job) -> Decodability:
    kw: dict[str, Any] = {'seed': job.seed, 'repeat': job.repeat, 'head_seed': job.head_seed,
                          'rate': job.rate, **dict(zip(_NAMES, job.params, strict=True))}
    n_cal = len(job.calibration)
    with one_blas_thread():
        cal = synthetic_runs(job.calibration, run_normals=job.run_normals[:n_cal], **kw)
        test = synthetic_runs(job.test, first_run=n_cal, run_normals=job.run_normals[n_cal:],
                              **kw)
    return measure(cal, test, channels=job.channels)


def _jobs_of(calibration: Sequence[RunSchedule], test: Sequence[RunSchedule],
             params: tuple[float, ...], *, seed: int, repeats: int, head_seed: int,
             channels: Sequence[str], rate: float) -> list[_Job]:
    normals = _stratified_normals(seed, repeats, len(calibration) + len(test))
    return [_Job(tuple(calibration), tuple(test), tuple(channels), params, seed, r, head_seed,
                 rate, normals[r]) for r in range(repeats)]


def _stratified_normals(seed: int, repeats: int, n_runs: int) -> np.ndarray:
    """Standard normal draws of the run conditions of ``repeats`` sessions, Latin-hypercube
    stratified over the sessions: a few sessions then cover good and bad runs evenly, and their
    mean is far steadier than with independent draws (run conditions vary figures most).

    Returns
    -------
    z : ndarray, shape (repeats, n_runs, RunConditions.N_DRAWS)
    """
    from scipy.stats import norm, qmc

    from mindgrasp_eeg.synthetic import RunConditions

    n = RunConditions.N_DRAWS
    lhs = qmc.LatinHypercube(d=n_runs * n, seed=np.random.default_rng([seed, 4]))
    return norm.ppf(lhs.random(repeats)).reshape(repeats, n_runs, n)


def _label(params: tuple[float, ...]) -> str:
    return 'virtual subject ({})'.format(', '.join(
        f'{k} {v:g}' for k, v in zip(_NAMES, params, strict=True)))


def synthetic_figures(calibration: Sequence[RunSchedule], test: Sequence[RunSchedule], *,
                      separability: float = 1.0, lateral_separability: float = 1.0,
                      rest_separability: float = 0.0, nonstationarity: float = 0.0,
                      seed: int = 0, repeats: int = 4,
                      head_seed: int = 0, channels: Sequence[str] = NAUTILUS_32,
                      rate: float = NAUTILUS_RATE, jobs: int = 1) -> Decodability:
    """Decodability of the virtual subject, averaged over ``repeats`` sessions.

    Each repetition generates every calibration and test run with its own seed (from ``seed``),
    so the runs differ in noise and, with ``nonstationarity``, in conditions (stratified over
    the repetitions); the same ``seed`` gives the same runs at any setting (common random
    numbers: differences between settings are not noise). ``jobs`` > 1 measures repetitions in
    parallel processes.
    """
    params = (separability, lateral_separability, rest_separability, nonstationarity)
    todo = _jobs_of(calibration, test, params, seed=seed, repeats=repeats, head_seed=head_seed,
                    channels=channels, rate=rate)
    if jobs <= 1 or repeats <= 1:
        return average([_measure_job(j) for j in todo], _label(params))
    with ProcessPoolExecutor(max_workers=min(jobs, repeats)) as pool:
        return average(list(pool.map(_measure_job, todo)), _label(params))


