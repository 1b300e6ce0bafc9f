"""robot:=panda: the simulator node loads the Franka Emika Panda (seven joints, the Franka Hand's
two prismatic fingers, one a URDF mimic of the other) in its own process, over real DDS: seven
joints at home on /joint_states that follow seven velocities on /arm_controller/commands, six
velocities refused with one line naming the count, and both fingers closing together."""

from __future__ import annotations

import numpy as np
import pytest
from test_sim_node import Probe, spin_until, start

from mindgrasp_common.robot_description import load_robot

pytestmark = pytest.mark.slow


def test_panda_has_seven_joints_that_follow_velocity_commands(rclpy_ctx, spawn_node):
    panda = load_robot('panda')
    proc = start(spawn_node, 'robot:=panda')
    assert "with the robot 'panda'" in proc.output()
    probe = Probe(rclpy_ctx)
    assert spin_until(rclpy_ctx, probe.node, lambda: len(probe.joints) > 20, 120), proc.output()
    assert list(probe.joints[-1].name) == list(panda.arm_joints)
    assert len(panda.arm_joints) == 7
    np.testing.assert_allclose(probe.q(), panda.home_pose, atol=0.01)
    assert probe.matched(), proc.output()
    # a six-joint command is refused, one line naming the count and the fix; the arm holds
    probe.command(np.full(6, 0.3))
    assert proc.wait_for_output('the arm has 7 joints; send 7 velocities', 60), proc.output()
    np.testing.assert_allclose(probe.q(), panda.home_pose, atol=0.01)
    # the base and the seventh (hand roll) joint move at the commanded rate, the others hold
    v = np.array([0.3, 0.0, 0.0, 0.0, 0.0, 0.0, -0.4])
    assert probe.drive(v, lambda: probe.q()[0] > panda.home_pose[0] + 0.3), proc.output()
    np.testing.assert_allclose(np.asarray(probe.joints[-1].velocity), v, atol=0.05)
    assert probe.q()[6] < panda.home_pose[6] - 0.3
    np.testing.assert_allclose(probe.q()[1:6], panda.home_pose[1:6], atol=0.01)
    proc.stop()


def test_panda_fingers_close_together_on_command(rclpy_ctx, spawn_node):
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

    panda = load_robot('panda')
    proc = start(spawn_node, 'robot:=panda')
    probe = Probe(rclpy_ctx)
    fingers: list = []
    probe.node.create_subscription(JointState, '/gripper/joint_states', fingers.append, 100)
    assert probe.matched(), proc.output()
    assert spin_until(rclpy_ctx, probe.node, lambda: bool(fingers) and np.allclose(
        fingers[-1].position, panda.gripper.open, atol=0.002), 60), proc.output()
    probe.grip_pub.publish(probe.Float64MultiArray(data=[1.0]))
    assert spin_until(rclpy_ctx, probe.node, lambda: np.allclose(
        fingers[-1].position, panda.gripper.closed, atol=0.002), 60), \
        (fingers[-1].position, proc.output())
    assert list(fingers[-1].name) == list(panda.gripper.joints)
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
