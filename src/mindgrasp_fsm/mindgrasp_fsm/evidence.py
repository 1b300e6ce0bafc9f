"""Evidence for one binary decision, accumulated over decoder windows (dynamic stopping).

A decision ("confirm this object": both hands against rest; "cancel": both feet against the rest
of the classes) is taken only when the decoder's calibrated probabilities have favoured it for
long enough. Each new prediction adds its log-probability ratio

    llr = log p(for) - log p(against),  clipped to +-``clip``,

weighted by the time it covers (the gap to the previous prediction, at most ``max_gap`` s), so the
evidence is a time integral in nat-seconds and does not depend on the decoder's window step. The
decision is taken when the sum reaches ``threshold``: holding ``p(for) / p(against) = e`` (73 %
against the other side) for 2 s gives 2 nat-s. With a ``reject_threshold`` the same sum also
decides the other way when it falls to ``-reject_threshold`` (Wald's sequential probability
ratio test: both answers are active imagery, e.g. both hands "yes" and both feet "no"); without
one the sum never falls below 0 (a CUSUM, Page 1954), so evidence against the decision before
the person starts to imagine cannot delay it afterwards.

When the decoder knows no ``rest`` class (a model of the four imagery classes only), "against"
is every other class the decoder knows. Either side may be a *set* of classes (a person's answer
pair, :mod:`mindgrasp_common.answer_pair`: "yes" = any imagery against "no" = rest): its
probability is the sum over the set.

    >>> import numpy as np
    >>> from mindgrasp_common.types import Prediction
    >>> ev = Evidence(2, [4], threshold=1.0)
    >>> ev.reset(since=0.0)
    >>> for k in range(1, 11):       # 1 s of p(both hands) = 3 p(rest)
    ...     done = ev.update(Prediction(2, 0.0, stamp=k * 0.1, classes=(0, 1, 2, 3, 4),
    ...                                 probabilities=np.array([.05, .05, .6, .1, .2])))
    >>> round(ev.value, 3), done
    (1.099, True)
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from mindgrasp_common.types import Prediction

__all__ = ['Evidence', 'log_ratio']

_FLOOR = 1e-6     # probabilities are clipped here: a 0 from a float32 message is not certainty


def log_ratio(probabilities: np.ndarray, classes: Sequence[int],
              for_class: int | Sequence[int], against: Sequence[int]) -> float | None:
    """``log sum p(for_class) - log sum p(against)`` from one prediction's probabilities.

    ``classes`` are the decoder's class indices in the order of ``probabilities``;
    ``for_class`` is one class or a set of them (those the decoder does not know are left out);
    classes of ``against`` the decoder does not know are left out, and when none is known
    "against" is every other class. None when no class of ``for_class`` is known to the decoder
    or the probabilities do not match ``classes``.
    """
    p = np.asarray(probabilities, dtype=float)
    classes = [int(c) for c in classes]
    group = [int(for_class)] if isinstance(for_class, (int, np.integer)) else \
        [int(c) for c in for_class if int(c) in classes]
    if p.shape != (len(classes),) or not group or group[0] not in classes or \
            not np.isfinite(p).all():
        return None
    known = [c for c in against if c in classes and c not in group]
    if not known:
        known = [c for c in classes if c not in group]
    if len(group) == 1:
        p_for = max(p[classes.index(group[0])], _FLOOR)
    else:
        p_for = max(sum(p[classes.index(c)] for c in group), _FLOOR)
    p_against = max(sum(p[classes.index(c)] for c in known), _FLOOR)
    return math.log(p_for) - math.log(p_against)


class Evidence:
    """Accumulated evidence (nat-s) for one decision; see the module docstring.

    Parameters
    ----------
    for_class : int or sequence of int
        Decoder class (or set of classes) that speaks for the decision (2 both hands, 3 both
        feet; ``(0, 1, 2, 3)`` any imagery).
    against : sequence of int
        Classes that speak against it (4 rest, ...).
    threshold : float
        Evidence (nat-s) at which the decision is taken.
    clip : float
        Largest log-ratio (nats) one prediction may add or remove.
    max_gap : float
        Longest time (s) one prediction stands for (a gap in the predictions adds nothing).
    reject_threshold : float or None
        Evidence (nat-s) against the decision at which it is rejected; None: never rejected,
        the sum stays >= 0.
    """

    def __init__(self, for_class: int | Sequence[int], against: Sequence[int], *,
                 threshold: float, clip: float = 2.0, max_gap: float = 0.25,
                 reject_threshold: float | None = None) -> None:
        self.for_class: int | list[int] = int(for_class) if isinstance(
            for_class, (int, np.integer)) else [int(c) for c in for_class]
        self.against = [int(c) for c in against]
        self.threshold, self.clip, self.max_gap = float(threshold), float(clip), float(max_gap)
        self.reject_threshold = reject_threshold
        self.reset()

    def reset(self, since: float = -math.inf) -> None:
        """Forget the evidence; only predictions stamped after ``since`` (s) count from now."""
        self.value = 0.0
        self.peak = 0.0
        self.n_windows = 0
        self._last_stamp = float(since)

    @property
    def reached(self) -> bool:
        """Whether the evidence has reached the threshold."""
        return self.value >= self.threshold

    @property
    def rejected(self) -> bool:
        """Whether the evidence against the decision has reached ``reject_threshold``."""
        return self.reject_threshold is not None and self.value <= -self.reject_threshold

    @property
    def fraction(self) -> float:
        """Evidence as a fraction of the threshold (0..1), for displays."""
        return min(max(self.value / self.threshold, 0.0), 1.0) if self.threshold > 0 else 1.0

    def update(self, prediction: Prediction | None) -> bool:
        """Add ``prediction`` if it is newer than the last one counted; True once reached (see
        :attr:`rejected` for the other answer).

        A prediction without probabilities (or without its decoder's ``classes``) adds nothing.
        """
        if prediction is None or not prediction.stamp > self._last_stamp:
            return self.reached
        gap = prediction.stamp - self._last_stamp
        self._last_stamp = prediction.stamp
        if prediction.probabilities is None or prediction.classes is None:
            return self.reached
        llr = log_ratio(prediction.probabilities, prediction.classes, self.for_class,
                        self.against)
        if llr is None:
            return self.reached
        llr = min(max(llr, -self.clip), self.clip)
        floor = 0.0 if self.reject_threshold is None else -self.reject_threshold
        self.value = max(self.value + llr * min(gap, self.max_gap), floor)
        self.peak = max(self.peak, self.value)
        self.n_windows += 1
        return self.reached
