"""The third-person scene camera (Simulation.render_scene) that feeds the participant display."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_sim.errors import SimError
from mindgrasp_sim.simulation import Simulation


def green_pixels(rgb: np.ndarray) -> int:
    """Pixels where green clearly dominates (the training robot's colour)."""
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    return int(np.count_nonzero((g > r + 40) & (g > b + 40)))


def test_scene_view_shows_the_training_robot_green_and_semi_transparent():
    with Simulation('set_locations', trainer_robot=True) as s, Simulation('set_locations') as ref:
        s.set_joint_velocities(np.array([0.6, 0.2, 0, 0, 0, 0]), robot='trainer')
        s.step(int(1.5 * s.physics_hz))
        rgb = s.render_scene(160, 120)
        alone = ref.render_scene(160, 120)
        assert rgb.shape == (120, 160, 3) and rgb.dtype == np.uint8
        assert green_pixels(alone) == 0
        assert green_pixels(rgb) > 150
        # semi-transparent: the training robot's pixels mix its green with what is behind it,
        # so they are darker than its pure colour rendered alone
        ys, xs = np.nonzero(rgb[:, :, 1].astype(int) > rgb[:, :, 0] + 40)
        assert rgb[ys, xs, 1].mean() < 200
        # the user's arm is in both views at the same place (rendering the ghost moves nothing)
        np.testing.assert_allclose(s.joint_positions('user'), s.home_pose, atol=2e-3)


def test_scene_view_has_ground_and_objects():
    with Simulation('set_locations') as s:
        rgb = s.render_scene(160, 120)
        r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
        assert np.count_nonzero((r > 150) & (g < 80) & (b < 80)) > 5     # a red object
        assert np.count_nonzero((b > 150) & (r < 80)) > 5                 # a blue object
        assert np.count_nonzero((abs(r - g) < 10) & (r > 140)) > 0.3 * r.size   # ground


def test_scene_view_size_is_checked():
    with Simulation('set_locations') as s, pytest.raises(SimError, match='Scene camera width'):
        s.render_scene(2, 120)
