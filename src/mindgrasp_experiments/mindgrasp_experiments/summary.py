"""Figures of a set of trial records, with Wilson 95 % confidence intervals, and the paper's.

Rates are fractions (0..1); times simulated seconds. ``summarise(records)`` is what the trial
manager logs, ``summary.json`` holds and ``report.md`` shows.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence

from mindgrasp_experiments.protocols import SHAPES
from mindgrasp_experiments.records import TrialRecord, shape_of

__all__ = ['PAPER', 'summarise', 'wilson']

#: The MIndGrasp paper's results (fractions; seconds).
PAPER = {
    'set_locations': {'success_rate': 0.356, 'correct_choice_rate': 0.144,
                      'correct_and_successful_rate': 0.031, 'mean_duration_s': 246.4,
                      'trials': 160},
    'random_locations': {'success_rate': 0.335, 'success_rate_cube': 0.605,
                         'success_rate_cylinder': 0.176, 'success_rate_sphere': 0.133,
                         'trials': 507},
}


def wilson(successes: int, n: int, confidence: float = 0.95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (NaN, NaN when ``n`` is 0)."""
    if n <= 0:
        return (math.nan, math.nan)
    from scipy.stats import binomtest

    ci = binomtest(int(successes), int(n)).proportion_ci(confidence_level=confidence,
                                                         method='wilson')
    return (float(ci.low), float(ci.high))


def _rate(records: Sequence[TrialRecord], field: str) -> dict:
    k = sum(bool(getattr(r, field)) for r in records)
    n = len(records)
    low, high = wilson(k, n)
    return {'count': k, 'trials': n, 'rate': k / n if n else math.nan, 'ci95': [low, high]}


def _stats(values: list[float]) -> tuple[float, float]:
    values = [v for v in values if math.isfinite(v)]
    if not values:
        return math.nan, math.nan
    return statistics.fmean(values), statistics.median(values)


def summarise(records: Sequence[TrialRecord]) -> dict:
    """Success, correct choice, correct and successful (each with its Wilson 95 % CI), per
    desired shape, times (s), failures by kind, decoder figures."""
    records = list(records)
    out: dict = {'trials': len(records)}
    for field in ('success', 'correct_choice', 'correct_and_successful'):
        r = _rate(records, field)
        out[f'{field}_rate'] = r['rate']
        out[f'{field}_ci95'] = r['ci95']
        out[f'{field}_count'] = r['count']
    by_shape = {}
    for shape in SHAPES:
        rs = [r for r in records if shape_of(r.desired) == shape]
        by_shape[shape] = _rate(rs, 'success')
    out['success_by_shape'] = by_shape
    out['mean_time_to_grasp_s'], out['median_time_to_grasp_s'] = _stats(
        [r.time_to_grasp_s for r in records if r.success])
    out['mean_duration_s'], out['median_duration_s'] = _stats([r.duration_s for r in records])
    failures: dict[str, int] = {}
    for r in records:
        if r.failure:
            failures[r.failure] = failures.get(r.failure, 0) + 1
    out['failures'] = failures
    out['node_errors'] = failures.get('node_error', 0)
    out['decoder_accuracy'], _ = _stats([r.decoder_accuracy for r in records])
    out['mean_certainty'], _ = _stats([r.mean_certainty for r in records])
    out['mean_path_length_m'], _ = _stats([r.path_length_m for r in records])
    out['mean_class_switches'], _ = _stats([float(r.class_switches) for r in records])
    return out
