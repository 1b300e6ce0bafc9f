"""Fixtures of the vision tests: a headless PyBullet simulation and views of chosen scenes."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_vision.detector import CameraModel, ColourDetector


@pytest.fixture(scope='session')
def sim():
    """One 128x128 headless simulation shared by the vision tests (scenes are reloaded)."""
    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation

    s = Simulation(scene={'name': 'vision_test', 'objects': [
        {'shape': 'cube', 'colour': 'red', 'position': [0.5, 0.0]}]}, seed=0,
        camera=CameraConfig(width=128, height=128))
    yield s
    s.close()


@pytest.fixture(scope='session')
def placer(sim):
    from mindgrasp_vision.dataset import CameraPlacer

    return CameraPlacer(sim)


@pytest.fixture(scope='session')
def detector(sim) -> ColourDetector:
    k, width, height = sim.camera_intrinsics()
    return ColourDetector(intrinsics=CameraModel.from_k(width, height, k))


@pytest.fixture
def view(sim, placer):
    """``view(objects, target, distance, elevation_deg, azimuth_deg=None)`` loads a scene of
    ``objects`` (scene-file entries), points the camera at ``target`` (x, y, z m) and returns
    (rgb, depth)."""

    def _view(objects: list[dict], target, distance: float = 0.3, elevation_deg: float = 45.0,
              azimuth_deg: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        sim.load_scene({'name': 'vision_test', 'objects': objects})
        assert placer.look_at(np.asarray(target, float), distance, elevation_deg, azimuth_deg), \
            'the arm cannot reach this test view; change the test geometry'
        return sim.render_camera()

    return _view
