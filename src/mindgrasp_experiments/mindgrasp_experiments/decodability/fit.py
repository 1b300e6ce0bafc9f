"""Fit the virtual subject's decodability settings to a real subject's figures
(``mindgrasp eeg fit-virtual``).

A real subject's figures rest on few trials (EEGMMIDB: 7-8 per class and run), so each has a
sampling error of 5-12 points
(:meth:`~mindgrasp_experiments.decodability.figures.Decodability.standard_error`): a fit closer
than that is fitting chance.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE
from mindgrasp_experiments.decodability.figures import Decodability, average
from mindgrasp_experiments.decodability.paradigm import RunSchedule
from mindgrasp_experiments.decodability.synthetic import (
    _NAMES,
    FIT_START,
    PARAMETER_BOUNDS,
    _jobs_of,
    _label,
    _measure_job,
)

__all__ = ['FitResult', 'default_jobs', 'fit_virtual', 'score_errors']


@dataclass
class FitResult:
    """Outcome of :func:`fit_virtual`.

    Attributes
    ----------
    params : dict str -> float
        Fitted settings (keys of :data:`PARAMETER_BOUNDS`).
    real, synthetic : Decodability
        The target's figures and the virtual subject's with ``params`` (the fit's sessions).
    error : float
        Root mean square of the score differences over the figures (fraction).
    max_error : float
        Largest absolute score difference (fraction).
    n_evaluations : int
        Settings measured.
    check : Decodability or None
        The fitted subject on fresh sessions (other seeds): what it gives beyond the sessions
        it was fitted on.
    history : list of (dict, float)
        Every setting measured and its RMS error.
    """

    params: dict[str, float]
    real: Decodability
    synthetic: Decodability
    error: float
    max_error: float
    n_evaluations: int
    check: Decodability | None = None
    history: list[tuple[dict[str, float], float]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-ready content."""
        out = {'params': dict(self.params), 'error': self.error, 'max_error': self.max_error,
               'n_evaluations': self.n_evaluations, 'real': self.real.to_dict(),
               'synthetic': self.synthetic.to_dict(),
               'check': self.check.to_dict() if self.check is not None else None,
               'history': [{**params, 'error': err} for params, err in self.history]}
        if self.check is not None:
            errors = score_errors(self.real, self.check)
            out['check_error'] = _rms_of(np.array(list(errors.values())))
            out['check_max_error'] = float(max(abs(v) for v in errors.values()))
        return out


def score_errors(real: Decodability, synthetic: Decodability) -> dict[str, float]:
    """Synthetic minus real score per figure (fractions), figures measurable in both."""
    r, s = real.scores(), synthetic.scores()
    return {k: s[k] - r[k] for k in r if math.isfinite(r[k]) and math.isfinite(s[k])}


def fit_virtual(real: Decodability, calibration: Sequence[RunSchedule],
                test: Sequence[RunSchedule], *, channels: Sequence[str] = NAUTILUS_32,
                seed: int = 0, repeats: int = 24, iterations: int = 2, head_seed: int = 0,
                start: Mapping[str, float] | None = None, jobs: int = 1, check: bool = True,
                progress: Callable[[int], None] | None = None) -> FitResult:
    """Fit the virtual subject's decodability settings to a subject's figures.

    Damped Gauss-Newton (Levenberg-Marquardt) on the score differences: each iteration measures
    the current setting and one step up (or down) each parameter (a tenth of its range, for
    the slopes), then three damped steps towards the least-squares match, all in one parallel
    batch, and moves to the best setting measured so far. Every setting is measured with the
    same seeds (:func:`synthetic_figures`), so slopes and comparisons are between settings, not
    noise. At most ``1 + 7 * iterations`` settings, plus the check on fresh sessions.

    Parameters
    ----------
    real : Decodability
        The target figures (:func:`replay_figures`).
    calibration, test : sequence of RunSchedule
        The protocol of the virtual sessions (the real subject's, :meth:`RunSchedule.of`).
    channels : sequence of str
        Channels measured (the real subject's :func:`common_channels`).
    seed, repeats, head_seed : int
        Seeds of the virtual sessions and their number per setting; the virtual head.
    iterations : int
        Gauss-Newton iterations (>= 1).
    start : mapping, optional
        First setting (default: :data:`FIT_START`).
    jobs : int
        Parallel processes.
    check : bool
        Measure the fitted setting once more on ``2 * repeats`` sessions of other seeds
        (:attr:`FitResult.check`).
    progress : callable, optional
        Called with the number of settings measured so far after each batch.

    Returns
    -------
    FitResult
        The best setting measured.
    """
    if iterations < 1 or repeats < 1:
        msg = (f'fit_virtual needs iterations >= 1 and repeats >= 1; got iterations '
               f'{iterations}, repeats {repeats}.')
        raise EEGError(msg)
    lo = np.array([PARAMETER_BOUNDS[k][0] for k in _NAMES])
    hi = np.array([PARAMETER_BOUNDS[k][1] for k in _NAMES])
    span = hi - lo
    first = {**FIT_START, **(start or {})}
    x = np.clip(np.array([float(first[k]) for k in _NAMES]), lo, hi)
    figures = [name for name, v in real.scores().items() if math.isfinite(v)]
    target = np.array([real.score(name) for name in figures])
    cache: dict[tuple[float, ...], Decodability] = {}
    history: list[tuple[dict[str, float], float]] = []
    pool = ProcessPoolExecutor(max_workers=jobs) if jobs > 1 else None

    def key_of(v: np.ndarray) -> tuple[float, ...]:
        return tuple(round(float(a), 4) for a in np.clip(v, lo, hi))

    def residual(k: tuple[float, ...]) -> np.ndarray:
        r = np.array([cache[k].score(name) for name in figures]) - target
        return np.nan_to_num(r, nan=1.0)        # a figure the virtual subject lacks: far off

    def measure_all(points: Sequence[np.ndarray]) -> list[tuple[float, ...]]:
        keys = [key_of(v) for v in points]
        new = [k for k in dict.fromkeys(keys) if k not in cache]
        todo = [j for k in new for j in _jobs_of(calibration, test, k, seed=seed,
                                                  repeats=repeats, head_seed=head_seed,
                                                  channels=channels, rate=NAUTILUS_RATE)]
        done = list(pool.map(_measure_job, todo)) if pool else [_measure_job(j) for j in todo]
        for i, k in enumerate(new):
            cache[k] = average(done[i * repeats:(i + 1) * repeats], _label(k))
            history.append((dict(zip(_NAMES, k, strict=True)), _rms_of(residual(k))))
        if progress is not None and new:
            progress(len(cache))
        return keys

    try:
        step = 0.1 * span
        for _ in range(iterations):
            # one-sided slopes, stepping away from a bound
            h = np.where(x + step <= hi, step, -step)
            keys = measure_all([x] + [x + h[i] * np.eye(len(x))[i] for i in range(len(x))])
            r0 = residual(keys[0])
            steps = [k[i] - keys[0][i] for i, k in enumerate(keys[1:])]   # as rounded
            jac = np.stack([(residual(k) - r0) / steps[i] for i, k in enumerate(keys[1:])],
                           axis=1)
            # damped least squares in units of each range (the parameters differ in scale)
            ju = jac * span
            jtj, jtr = ju.T @ ju, ju.T @ r0
            tries = [x - span * np.linalg.solve(jtj + lam * (np.diag(np.diag(jtj)) + 1e-3 *
                                                             np.eye(len(x))), jtr)
                     for lam in (0.03, 0.3, 3.0)]
            measure_all(tries)
            best = min(cache, key=lambda k: _rms_of(residual(k)))
            moved = not np.allclose(best, x)
            x = np.array(best)
            if not moved:           # no better setting: look closer
                step = step / 2
        best = key_of(x)
        fresh = None
        if check:                   # other seeds than every setting of the search saw
            todo = _jobs_of(calibration, test, best, seed=seed + 1_000_003, repeats=2 * repeats,
                            head_seed=head_seed, channels=channels, rate=NAUTILUS_RATE)
            done = list(pool.map(_measure_job, todo)) if pool else [_measure_job(j)
                                                                     for j in todo]
            fresh = average(done, _label(best) + ', fresh sessions')
            if progress is not None:
                progress(len(cache) + 1)
    finally:
        if pool is not None:
            pool.shutdown()
    errors = score_errors(real, cache[best])
    return FitResult(dict(zip(_NAMES, best, strict=True)), real, cache[best],
                     _rms_of(residual(best)),
                     float(max(abs(v) for v in errors.values())) if errors else math.inf,
                     len(cache), fresh, history)


def _rms_of(r: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(r))))


def default_jobs() -> int:
    """Processes for a fit: the CPUs this process may use, at most 4."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:        # not on Linux
        n = os.cpu_count() or 1
    return max(1, min(4, n))
