"""The information transfer rate of the object selection (Wolpaw et al. 1998; 2002).

The person selects one of ``N`` objects per selection; a selection is a grasp of some object
(``correct_grasp`` or ``wrong_grasp``, :func:`mindgrasp_experiments.records.outcome_of`), right
with probability ``P``. Wolpaw's bits per selection assume equally likely targets and errors
spread evenly over the other ``N - 1`` objects:

    B = log2 N + P log2 P + (1 - P) log2((1 - P) / (N - 1))

The rate divides the bits of all selections by the time the person spent on them, trials
without a grasp included (they cost time and select nothing):

    ITR = B * selections / minutes

    >>> round(itr_bits_per_min(9, 0.8, selections=10, minutes=5.0), 3)
    3.696
"""

from __future__ import annotations

import math

__all__ = ['bits_per_selection', 'itr_bits_per_min']


def bits_per_selection(n_choices: int, p: float) -> float:
    """Wolpaw's bits per selection among ``n_choices`` (>= 2) with accuracy ``p`` (0..1).

    ``p = 1`` gives log2 N (the limit of ``P log2 P``); at or below chance (``p <= 1/N``,
    ``p = 0`` included) the selection carries no information: 0 (the formula would turn up
    again below chance, but a worse-than-chance selector tells nothing the user meant). NaN
    for a NaN ``p`` (no selection to judge).

        >>> bits_per_selection(9, 1.0) == math.log2(9)
        True
        >>> round(bits_per_selection(9, 0.8), 4)    # 3.1699 - 0.2575 - 1.0644
        1.848
        >>> round(bits_per_selection(4, 0.5), 4)    # 2 - 0.5 - 1.2925
        0.2075
        >>> bits_per_selection(9, 1 / 9), bits_per_selection(2, 0.0)
        (0.0, 0.0)
    """
    if n_choices < 2:
        msg = f'bits_per_selection: a selection needs at least 2 choices, got {n_choices}.'
        raise ValueError(msg)
    if math.isnan(p):
        return math.nan
    if not 0.0 <= p <= 1.0:
        msg = f'bits_per_selection: the accuracy is a fraction within 0..1, got {p}.'
        raise ValueError(msg)
    if p <= 1.0 / n_choices:
        return 0.0
    bits = math.log2(n_choices) + p * math.log2(p)
    if p < 1.0:
        bits += (1.0 - p) * math.log2((1.0 - p) / (n_choices - 1))
    return bits


def itr_bits_per_min(n_choices: int, p: float, selections: int, minutes: float) -> float:
    """Information transfer rate in bits per minute: ``bits_per_selection(n_choices, p) *
    selections / minutes``, ``minutes`` the whole time of the trials (with those that selected
    nothing). 0 when nothing was selected (no information got through); NaN without time.

        >>> itr_bits_per_min(9, 1.0, selections=2, minutes=1.0) == 2 * math.log2(9)
        True
        >>> itr_bits_per_min(9, math.nan, selections=0, minutes=3.0)
        0.0
    """
    if not minutes > 0.0:
        return math.nan
    if selections <= 0:
        return 0.0
    return bits_per_selection(n_choices, p) * selections / minutes
