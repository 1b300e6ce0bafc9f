"""A parallel-jaw gripper from its description: the xArm6's gripper (a linkage whose five other
joints are URDF mimics of its drive joint) picks each shape from above by friction alone and
lifts it above 0.22 m. PyBullet ignores <mimic>: the simulation couples the mimic joints to
their leader (gear constraints), or the finger pads turn out under load and the object slips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_common.robot_description import load_robot
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_sim.simulation import Simulation
from mindgrasp_sim.task import SUCCESS_HEIGHT

pytestmark = pytest.mark.slow


def one_object_scene(shape: str, xy: tuple[float, float]) -> dict:
    return {'name': 'one', 'objects': [{'shape': shape, 'colour': 'red', 'size': 0.05,
                                        'position': list(xy), 'yaw_deg': 0.0}]}


class Driver:
    """Joint-velocity moves of the simulated arm through the controller's kinematics (as the
    controller sends them at 60 Hz; nothing is teleported)."""

    def __init__(self, sim: Simulation, robot: str) -> None:
        self.sim = sim
        self.kin = GraspFsm.from_params(FsmParams(robot=robot)).kinematics
        self.vmax = np.asarray(load_robot(robot).max_velocity)

    def _send(self, err: np.ndarray, gain: float) -> None:
        v = gain * err
        v = v / max(1.0, float(np.max(np.abs(v) / self.vmax)))
        self.sim.set_joint_velocities(v)
        self.sim.step(4)

    def to_joints(self, q: np.ndarray, timeout: float = 8.0) -> None:
        for _ in range(int(timeout * 60)):
            err = q - self.sim.joint_positions()
            if np.max(np.abs(err)) < 0.003:
                break
            self._send(err, 3.0)
        self.sim.stop()

    def line(self, p1: np.ndarray, yaw: float, speed: float = 0.05) -> None:
        """Straight tool motion to ``p1`` (m), gripper pointing down at ``yaw`` (rad)."""
        p0 = self.kin.tool_position(self.sim.joint_positions())
        steps = int(np.linalg.norm(p1 - p0) / speed * 60) + 1
        for k in range(1, steps + 1):
            q = self.kin.grasp_ik(p0 + (p1 - p0) * k / steps, yaw, self.sim.joint_positions())
            assert q is not None
            self._send(q - self.sim.joint_positions(), 60.0)
        self.sim.stop()
        self.sim.step(10)

    def grasp(self) -> tuple[np.ndarray, float]:
        """Above the scene's one object, straight down, close: finger positions and the yaw."""
        x, y, _ = self.sim.objects()[0].position
        yaw = math.atan2(y, x) + math.pi
        self.to_joints(self.kin.grasp_ik(np.array([x, y, 0.15]), yaw, self.sim.joint_positions()))
        self.line(np.array([x, y, 0.03]), yaw)
        self.sim.set_gripper(1.0)
        self.sim.step(240)
        return self.sim.finger_positions(), yaw

    def lift(self, shape: str, yaw: float) -> None:
        """Straight up to 0.28 m; the object held and above the success height."""
        x, y, _ = self.sim.objects()[0].position
        self.line(np.array([x, y, 0.28]), yaw, speed=0.1)
        self.sim.step(120)
        held = self.sim.held_object()
        assert held is not None and held.shape == shape
        assert self.sim.objects()[0].position[2] > SUCCESS_HEIGHT


@pytest.mark.parametrize('shape', ['cube', 'cylinder', 'sphere'])
def test_xarm6_picks_each_shape_and_its_linkage_stays_coupled(shape):
    xarm = load_robot('xarm6')
    assert {m[0] for m in xarm.gripper.mimic} == set(xarm.gripper.joints[1:])
    with Simulation(one_object_scene(shape, (0.45, -0.1)), robot='xarm6') as sim:
        arm = Driver(sim, 'xarm6')
        fingers, yaw = arm.grasp()
        # stopped on the object, every joint of the linkage near the drive joint's angle
        assert 0.2 < fingers[0] < 0.8 * xarm.gripper.closed[0], fingers
        np.testing.assert_allclose(fingers, fingers[0], atol=0.2)
        arm.lift(shape, yaw)


@pytest.mark.parametrize('shape', ['cube', 'sphere'])
def test_panda_picks_with_its_two_fingers_moving_as_one(shape):
    """The Franka Hand: panda_finger_joint2 mimics panda_finger_joint1 (prismatic, 0.04 m open);
    both stop on the object at the same travel, and the seven-joint arm lifts it straight up
    through the redundant grasp IK."""
    panda = load_robot('panda')
    assert panda.gripper.mimic == (('panda_finger_joint2', 'panda_finger_joint1', 1.0, 0.0),)
    with Simulation(one_object_scene(shape, (0.45, -0.1)), robot='panda') as sim:
        arm = Driver(sim, 'panda')
        fingers, yaw = arm.grasp()
        # each finger stopped on the 5 cm object, about 25 mm from the closed position
        assert 0.02 < fingers[0] < 0.035, fingers
        assert abs(fingers[0] - fingers[1]) < 0.001, fingers
        arm.lift(shape, yaw)
