"""The Graz-BCI cue protocol (Pfurtscheller & Neuper 2001) as a seeded schedule of prompt events.

One trial::

    |-- fixation --|-- cue (arrow) --|------ move (imagery) ------|-- rest (random) --|
    0              2 s               3.25 s                       6 s                 6 s + ITI

The imagery period runs from cue onset to the end of ``move`` (4 s by default, as in BCI
Competition IV 2a); ``cue`` and ``move`` carry the class, ``fixation`` and ``rest`` carry
:data:`~mindgrasp_trainer.protocol.NO_CLASS`. An ``end`` event closes the session.
No ROS imports: the node, tests and offline labelling share this code.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence

import numpy as np

from mindgrasp_trainer.protocol import NO_CLASS, PromptEvent, TrainerError, balanced_order

__all__ = ['GrazProtocol', 'PromptSequencer']


def _check_duration(name: str, value: float, allow_zero: bool = False) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
        bound = 'zero or positive' if allow_zero else 'positive'
        msg = (
            f"The duration '{name}' must be a finite {bound} number of seconds; "
            f'{value} is invalid.'
        )
        raise TrainerError(msg)
    return value


class GrazProtocol:
    """Seeded Graz-BCI schedule: fixation, arrow cue, imagery, random rest; balanced classes.

    Parameters
    ----------
    n_trials : int
        Total number of trials; a multiple of ``len(classes)`` gives exactly balanced classes
        (``4 * n`` for n trials per class), otherwise counts differ by at most one.
    classes : sequence of int
        Class indices to cue (0 left hand, 1 right hand, 2 both hands, 3 both feet).
    fixation : float
        Fixation cross before the cue (s).
    cue : float
        Arrow on screen (s).
    imagery : float
        Imagery after the arrow disappears, phase ``move`` (s).
    rest_min, rest_max : float
        Inter-trial rest drawn uniformly from [rest_min, rest_max] (s).
    max_repeat : int
        Longest run of one class in a row; 0 means no limit.
    seed : int
        Seed of the class order and rest durations; same seed, same schedule.
    start_delay : float
        Time before the first fixation (s), e.g. for subscribers to connect.
    """

    paradigm = 'graz'

    def __init__(
        self,
        n_trials: int = 40,
        classes: Sequence[int] = (0, 1, 2, 3),
        fixation: float = 2.0,
        cue: float = 1.25,
        imagery: float = 2.75,
        rest_min: float = 1.5,
        rest_max: float = 2.5,
        max_repeat: int = 0,
        seed: int = 0,
        start_delay: float = 0.0,
    ) -> None:
        self.n_trials = n_trials
        self.classes = tuple(classes)
        self.fixation = fixation
        self.cue = cue
        self.imagery = imagery
        self.rest_min = rest_min
        self.rest_max = rest_max
        self.max_repeat = max_repeat
        self.seed = seed
        self.start_delay = start_delay

    def _check(self) -> None:
        for name in ('fixation', 'cue', 'imagery'):
            _check_duration(name, getattr(self, name))
        for name in ('rest_min', 'rest_max', 'start_delay'):
            _check_duration(name, getattr(self, name), allow_zero=True)
        if self.rest_min > self.rest_max:
            msg = (
                f"'rest_min' ({self.rest_min} s) is larger than 'rest_max' ({self.rest_max} s); "
                'swap them or make them equal for a fixed rest.'
            )
            raise TrainerError(msg)

    def class_order(self) -> np.ndarray:
        """Class of each trial, shape (n_trials,); balanced and seeded."""
        self._check()
        rng = np.random.default_rng(self.seed)
        return balanced_order(int(self.n_trials), self.classes, rng, int(self.max_repeat))

    def schedule(self) -> list[PromptEvent]:
        """All prompt events of the session in time order, ending with one ``end`` event.

        Returns
        -------
        events : list of PromptEvent
            ``4 * n_trials + 1`` events; onsets in seconds from the start of the protocol.
        """
        order = self.class_order()
        # rests come from their own stream, so changing them never changes the class order
        rest_rng = np.random.default_rng([int(self.seed), 1])
        rests = rest_rng.uniform(self.rest_min, self.rest_max, size=len(order))
        events: list[PromptEvent] = []
        t = float(self.start_delay)
        for trial, (k, rest) in enumerate(zip(order, rests, strict=True), start=1):
            k = int(k)
            for phase, cls, dur in (
                ('fixation', NO_CLASS, self.fixation),
                ('cue', k, self.cue),
                ('move', k, self.imagery),
                ('rest', NO_CLASS, float(rest)),
            ):
                events.append(PromptEvent(t, phase, trial, cls, float(dur), self.paradigm))
                t += float(dur)
        events.append(PromptEvent(t, 'end', len(order), NO_CLASS, 0.0, self.paradigm))
        return events

    def total_duration(self) -> float:
        """Length of the whole session (s), i.e. the onset of the ``end`` event."""
        return self.schedule()[-1].onset


class PromptSequencer:
    """Hands out the events of a fixed schedule as time passes.

    Parameters
    ----------
    events : sequence of PromptEvent
        Schedule in time order, the last one an ``end`` event.
    """

    def __init__(self, events: Sequence[PromptEvent]) -> None:
        if not events:
            msg = 'The prompt schedule is empty; build it with at least one trial.'
            raise TrainerError(msg)
        onsets = [e.onset for e in events]
        if any(b < a for a, b in itertools.pairwise(onsets)):
            msg = 'The prompt schedule is not in time order; sort the events by onset.'
            raise TrainerError(msg)
        self.events = list(events)
        self._next = 0
        self.current: PromptEvent | None = None

    @property
    def done(self) -> bool:
        """True once every event (including ``end``) was handed out."""
        return self._next >= len(self.events)

    def due(self, elapsed: float) -> list[PromptEvent]:
        """Events whose onset is at or before ``elapsed`` (s) and that were not handed out yet."""
        out = []
        while not self.done and self.events[self._next].onset <= elapsed:
            out.append(self.events[self._next])
            self._next += 1
        if out:
            self.current = out[-1]
        return out

    def stop(self, elapsed: float) -> PromptEvent | None:
        """End the session early at ``elapsed`` (s): an ``end`` event, or None if already ended."""
        if self.done:
            return None
        trial = self.current.trial if self.current is not None else 0
        end = PromptEvent(float(elapsed), 'end', trial, NO_CLASS, 0.0, self.events[-1].paradigm)
        self._next = len(self.events)
        self.current = end
        return end
