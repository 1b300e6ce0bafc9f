"""Grasp trials of the set-locations experiment: which object to grasp next, and the tally.

The paper's protocol: a desired object is drawn at random, the user drives the arm until a grasp
ends the trial, then the robot and all objects are reset and the next trial begins. This class
holds the ROS-free part (seeded draws and statistics); :mod:`trial_manager_node` wires it.
"""

from __future__ import annotations

import random
import statistics
from dataclasses import dataclass, field

from mindgrasp_common.types import SceneObject

__all__ = ['TrialOutcome', 'TrialPlanner']


@dataclass(frozen=True)
class TrialOutcome:
    """How one trial ended (times in seconds)."""

    trial: int
    desired: str
    grasped: str
    success: bool
    duration: float
    timed_out: bool = False

    @property
    def correct(self) -> bool:
        """The desired object was the one lifted."""
        return self.success and self.grasped == self.desired


@dataclass
class TrialPlanner:
    """Seeded choice of desired objects and the running tally.

    ``targets``: labels ("red cube") to cycle through; empty draws uniformly from the scene.
    """

    seed: int = 0
    targets: list[str] = field(default_factory=list)
    outcomes: list[TrialOutcome] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._rng = random.Random(self.seed)

    def next_target(self, trial: int, scene: list[SceneObject]) -> SceneObject:
        """The desired object of ``trial`` (1-based) among ``scene``."""
        if not scene:
            msg = 'The scene has no objects (is /sim/objects published?); cannot choose a target.'
            raise ValueError(msg)
        if self.targets:
            label = self.targets[(trial - 1) % len(self.targets)]
            for obj in scene:
                if obj.label == label:
                    return obj
            known = ', '.join(sorted(o.label for o in scene))
            msg = f'Target {label!r} is not in the scene; the scene has: {known}.'
            raise ValueError(msg)
        return scene[self._rng.randrange(len(scene))]

    def record(self, outcome: TrialOutcome) -> None:
        self.outcomes.append(outcome)

    def summary(self) -> dict[str, float | int]:
        """Trials, grasp success rate, correct-object rate, mean/median trial time (s)."""
        n = len(self.outcomes)
        times = [o.duration for o in self.outcomes if o.success]
        return {
            'trials': n,
            'success_rate': sum(o.success for o in self.outcomes) / n if n else 0.0,
            'correct_rate': sum(o.correct for o in self.outcomes) / n if n else 0.0,
            'timeouts': sum(o.timed_out for o in self.outcomes),
            'mean_time_s': statistics.fmean(times) if times else float('nan'),
            'median_time_s': statistics.median(times) if times else float('nan'),
        }
