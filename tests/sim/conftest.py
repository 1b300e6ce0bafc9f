"""Fixtures of the simulation tests: headless PyBullet worlds, closed after each test."""

from __future__ import annotations

import pytest

from mindgrasp_sim.camera import CameraConfig
from mindgrasp_sim.simulation import Simulation


@pytest.fixture
def sim():
    """The set-locations scene, 128 x 128 camera, seed 0."""
    s = Simulation('set_locations', seed=0, camera=CameraConfig(128, 128, 10.0))
    yield s
    s.close()


@pytest.fixture
def random_sim():
    s = Simulation('random_locations', seed=3)
    yield s
    s.close()
