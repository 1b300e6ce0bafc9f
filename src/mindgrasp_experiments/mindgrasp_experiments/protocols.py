"""The paper's grasp protocols: what each trial asks for, drawn from (seed, trial) alone.

``set_locations``: the 9 objects of ``config/scenes/set_locations.yaml`` (3 shapes x 3 colours,
0.5 m from the base); each trial names a desired object drawn at random, and the subject drives
the arm to it through EEG -> classifier -> controller. The scene is reset before each trial.

``random_locations``: one object per trial (random shape, colour, size 0.04-0.06 m and yaw) at a
random radius of 0.2-0.7 m (uniform over the annulus area) and angle of -170..170 deg; the
controller finds and grasps it autonomously.

Every draw depends on ``(seed, trial)`` only (``numpy.random.default_rng([seed, trial])``), so a
trial is the same whichever worker runs it and whatever ran before it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ['PROTOCOLS', 'RandomTrial', 'random_locations_trial', 'set_locations_target']

PROTOCOLS = ('set_locations', 'random_locations')
SHAPES = ('cube', 'cylinder', 'sphere')
COLOURS = ('red', 'yellow', 'blue')


def _rng(seed: int, trial: int, stream: int) -> np.random.Generator:
    return np.random.default_rng([int(seed), int(trial), int(stream)])


def set_locations_target(seed: int, trial: int, n_objects: int) -> int:
    """Index (0..n_objects-1, in /sim/objects id order) of the desired object of ``trial``."""
    if n_objects < 1:
        msg = 'The scene has no objects; cannot choose a desired object.'
        raise ValueError(msg)
    return int(_rng(seed, trial, 1).integers(n_objects))


@dataclass(frozen=True)
class RandomTrial:
    """Where one random-locations trial's object stands (m, deg) and what it is."""

    trial: int
    shape: str
    colour: str
    radius: float
    angle_deg: float
    size: float
    yaw_deg: float

    @property
    def label(self) -> str:
        return f'{self.colour} {self.shape}'

    def scene(self) -> dict:
        """A one-object scene mapping (the format of ``config/scenes/*.yaml``)."""
        return {
            'name': f'random_locations_trial_{self.trial}',
            'seed': self.trial,
            'defaults': {'density': 600.0, 'friction': 0.9, 'rolling_friction': 0.003,
                         'spinning_friction': 0.001},
            'objects': [{'shape': self.shape, 'colour': self.colour, 'radius': self.radius,
                         'angle_deg': self.angle_deg, 'size': self.size,
                         'yaw_deg': self.yaw_deg}],
        }


def random_locations_trial(seed: int, trial: int, radius: tuple[float, float] = (0.2, 0.7),
                           angle_deg: tuple[float, float] = (-170.0, 170.0),
                           size: tuple[float, float] = (0.04, 0.06)) -> RandomTrial:
    """The object of random-locations ``trial`` (1-based)."""
    rng = _rng(seed, trial, 2)
    shape = SHAPES[int(rng.integers(len(SHAPES)))]
    r = math.sqrt(rng.uniform(radius[0] ** 2, radius[1] ** 2))
    return RandomTrial(
        trial=trial, shape=shape, colour=COLOURS[int(rng.integers(len(COLOURS)))],
        radius=float(r), angle_deg=float(rng.uniform(*angle_deg)),
        size=float(rng.uniform(*size)),
        yaw_deg=0.0 if shape == 'sphere' else float(rng.uniform(-45.0, 45.0)))
