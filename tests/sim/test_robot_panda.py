"""robot:=panda: the simulator node loads the Franka Emika Panda (seven joints, the Franka Hand's
two prismatic fingers, one a URDF mimic of the other) in its own process, over real DDS: six
velocities refused with one line naming the count, no self-collision at the wrist. (Seven
joints at home that follow seven velocities, both fingers closing: tests/sim/test_robot_xarm6.py,
parametrised over both arms.)"""

from __future__ import annotations

import numpy as np
import pytest
from test_sim_node import Probe, spin_until, start

from mindgrasp_common.robot_description import load_robot

pytestmark = pytest.mark.slow


def test_panda_refuses_six_velocities_naming_its_seven_joints(rclpy_ctx, spawn_node):
    panda = load_robot('panda')
    proc = start(spawn_node, 'robot:=panda')
    probe = Probe(rclpy_ctx)
    assert probe.matched(), proc.output()
    # a six-joint command is refused, one line naming the count and the fix; the arm holds
    probe.command(np.full(6, 0.3))
    assert proc.wait_for_output('the arm has 7 joints; send 7 velocities', 60), proc.output()
    assert spin_until(rclpy_ctx, probe.node, lambda: len(probe.joints) > 5, 60), proc.output()
    np.testing.assert_allclose(probe.q(), panda.home_pose, atol=0.01)
    assert 'Traceback' not in proc.output()
    proc.stop()


def test_the_hand_and_link_7_never_collide():
    """panda_hand hangs from panda_link7 through the virtual panda_link8 (two fixed joints) and
    their meshes overlap: welded links do not collide, so turning the wrist reports no
    self-collision (PyBullet's EXCLUDE_PARENT alone spared only link 8)."""
    from mindgrasp_sim.simulation import Simulation

    with Simulation(robot='panda', n_objects=0) as sim:
        seen: set[str] = set()
        for step in range(400):
            v = np.zeros(7)
            v[5], v[6] = (0.5, 1.5) if step < 200 else (-0.5, -1.5)
            sim.set_joint_velocities(v)
            sim.step(2)
            seen |= set(sim.collisions())
        assert not seen
