"""Shared pieces of the cue protocols: prompt events, balanced class orders (class names and
``NO_CLASS`` from mindgrasp_common).

No ROS imports: the Graz-BCI schedule and the MIndGrasp Trainer use these, and so do offline tools
that label recorded EEG from prompts.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mindgrasp_common.mi import CLASS_NAMES, NO_CLASS

__all__ = [
    'CLASS_NAMES',
    'NO_CLASS',
    'PHASES',
    'PromptEvent',
    'TrainerError',
    'balanced_order',
    'check_classes',
]

#: Phase names of mindgrasp_msgs/Prompt.
PHASES: tuple[str, ...] = ('fixation', 'cue', 'move', 'wait', 'rest', 'end')


class TrainerError(ValueError):
    """Bad parameter or input of a trainer protocol; the message names the value and the fix."""


@dataclass(frozen=True)
class PromptEvent:
    """One phase of a cue protocol, the content of one mindgrasp_msgs/Prompt.

    Attributes
    ----------
    onset : float
        Planned start of the phase (s), from the start of the protocol.
    phase : str
        One of :data:`PHASES`.
    trial : int
        Trial number, from 1 (the last trial's number for ``end``).
    class_index : int
        Class asked for (0..3), or :data:`NO_CLASS` during fixation, rest and end.
    duration : float
        Planned duration of the phase (s); 0 for ``end``.
    paradigm : str
        ``'graz'`` or ``'trainer'``.
    """

    onset: float
    phase: str
    trial: int
    class_index: int
    duration: float
    paradigm: str

    @property
    def class_name(self) -> str:
        """Name of the class asked for, '' when none."""
        return CLASS_NAMES[self.class_index] if self.class_index != NO_CLASS else ''


def check_classes(classes: Sequence[int]) -> tuple[int, ...]:
    """Validate a list of class indices; return it as a tuple of ints.

    Raises
    ------
    TrainerError
        When the list is empty, has duplicates or holds an index outside 0..3.
    """
    out = tuple(int(c) for c in classes)
    if not out:
        msg = "The parameter 'classes' is empty; give at least one class index from 0 to 3."
        raise TrainerError(msg)
    bad = [c for c in out if not 0 <= c < len(CLASS_NAMES)]
    if bad:
        msg = (
            f"The parameter 'classes' holds {bad}, which are not class indices; use values from "
            f'0 to 3 (0 left hand, 1 right hand, 2 both hands, 3 both feet).'
        )
        raise TrainerError(msg)
    if len(set(out)) != len(out):
        msg = f"The parameter 'classes' {list(out)} has duplicates; list each class once."
        raise TrainerError(msg)
    return out


def balanced_order(
    n_trials: int,
    classes: Sequence[int],
    rng: np.random.Generator,
    max_repeat: int = 0,
) -> np.ndarray:
    """Random class order in which every class appears equally often.

    Parameters
    ----------
    n_trials : int
        Total number of trials. When it is not a multiple of ``len(classes)``, the remainder goes
        to randomly chosen distinct classes, so counts differ by at most one.
    classes : sequence of int
        Class indices to draw from.
    rng : numpy.random.Generator
        Source of randomness (seeded by the caller; same seed, same order).
    max_repeat : int
        Longest allowed run of one class in a row; 0 means no limit.

    Returns
    -------
    order : ndarray of int, shape (n_trials,)
    """
    classes = check_classes(classes)
    if n_trials < 1:
        msg = f"The number of trials 'n_trials' must be at least 1; {n_trials} is invalid."
        raise TrainerError(msg)
    if max_repeat < 0:
        msg = f"'max_repeat' must be 0 (no limit) or a positive run length; {max_repeat} is bad."
        raise TrainerError(msg)
    k = len(classes)
    counts = np.full(k, n_trials // k)
    counts[rng.permutation(k)[: n_trials % k]] += 1
    if max_repeat == 0:
        order = np.repeat(np.asarray(classes), counts)
        return rng.permutation(order)
    # Sequential draw weighted by the remaining counts, never extending a run past max_repeat;
    # a dead end (only the blocked class left) restarts the draw from the same generator.
    for _ in range(1000):
        left = counts.copy()
        order: list[int] = []
        run = 0
        while left.sum():
            allowed = left > 0
            if order and run >= max_repeat:
                allowed[classes.index(order[-1])] = False
            if not allowed.any():
                break
            p = left * allowed
            i = int(rng.choice(k, p=p / p.sum()))
            run = run + 1 if order and order[-1] == classes[i] else 1
            order.append(classes[i])
            left[i] -= 1
        if len(order) == n_trials:
            return np.asarray(order)
    msg = (
        f'No class order of {n_trials} trials over {len(classes)} classes keeps runs to '
        f"{max_repeat}; raise 'max_repeat' or add classes."
    )
    raise TrainerError(msg)
