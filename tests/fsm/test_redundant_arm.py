"""Seven-joint arms (ROS-free): the Panda's URDF kinematics give a (6, 7) Jacobian, the grasp IK
spends the redundant joint on staying near home and inside the limits, the twist input of the
simulator does the same only while a twist is commanded, the controller's parameters and its
camera tilt joint follow the description, and a six-joint arm computes as before."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_common.redundancy import redundancy_step
from mindgrasp_common.robot_description import load_robot
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.grasp_fsm import GraspFsm, pan_direction, tilt_direction, wrist_tilt
from mindgrasp_fsm.params import FsmParams
from mindgrasp_sim.control import velocities_from_twist


@pytest.fixture(scope='module')
def panda() -> GraspFsm:
    return GraspFsm.from_params(FsmParams(robot='panda'))


def test_the_panda_controller_has_seven_joints(panda: GraspFsm) -> None:
    p = panda.params
    assert panda.n_joints == 7 and len(p.home_position) == len(p.max_joint_velocity) == 7
    # the one acceleration limit of the parameter file, given to each of the seven joints
    assert p.max_joint_acceleration == [2.0] * 7
    # the wrist pitch joint that tilts the camera is joint 6; it tilts it forward, so the
    # controller turns it the other way round from joint 5 of the six-joint arms
    assert panda.tilt_joint == 5 and panda.tilt_sign == -1.0
    for name in ('xarm6', 'mindgrasp_arm'):
        six = GraspFsm.from_params(FsmParams(robot=name))
        assert (six.tilt_joint, six.tilt_sign) == (4, 1.0)
    assert tilt_direction(None, [0.0] * 7, 5) == 1.0


def test_the_jaco_turns_and_tilts_as_its_model_says() -> None:
    """The Jaco's joint 1 axis points down (a positive velocity turns it right) and its
    60-degree wrist has no pitch joint: the controller reads both from the robot model; every
    other shipped robot keeps joint 1 as the left turn and its tilt joint alone."""
    jaco = GraspFsm.from_params(FsmParams(robot='jaco'))
    assert (jaco.pan_sign, jaco.wrist_tilt, jaco.tilt_joint) == (-1.0, True, 4)
    for name in ('mindgrasp_arm', 'xarm6', 'panda', 'iiwa_franka_hand'):
        other = GraspFsm.from_params(FsmParams(robot=name))
        assert (other.pan_sign, other.wrist_tilt) == (1.0, False), name
    assert pan_direction(None, [0.0] * 6) == 1.0 and not wrist_tilt(None, [0.0] * 6, 4)


@pytest.mark.parametrize(('values', 'match'), [
    ({'joint_names': [f'j{i}' for i in range(5)]},
     r"'joint_names' lists 5 joints; the controller drives arms of 6 or 7 joints"),
    ({'joint_names': [f'j{i}' for i in range(7)]},
     r"'home_position' must have 7 entries \(one per arm joint in 'joint_names'\), got 6"),
    ({'robot': 'panda', 'max_joint_acceleration': [1.0, 2.0, 2.0, 2.0, 2.0, 2.0]},
     r"'max_joint_acceleration' must have 7 entries"),
    ({'robot': 'panda', 'approach_joint': 8}, r"'approach_joint'"),
])
def test_bad_joint_counts_name_the_problem(values: dict, match: str) -> None:
    with pytest.raises(FsmError, match=match):
        FsmParams.from_dict(values)


def test_the_jacobian_is_six_by_seven_and_matches_finite_differences(panda: GraspFsm) -> None:
    kin = panda.kinematics
    q = np.array(load_robot('panda').home_pose) + 0.1
    jac = kin.jacobian(q)
    assert jac.shape == (6, 7)
    eps = 1e-6
    for i in range(7):
        dq = np.zeros(7)
        dq[i] = eps
        dp = (kin.tool_position(q + dq) - kin.tool_position(q - dq)) / (2 * eps)
        np.testing.assert_allclose(jac[:3, i], dp, atol=1e-6)


def test_the_grasp_ik_reaches_and_the_redundant_joint_returns_home(panda: GraspFsm) -> None:
    """Out along a 30 cm line and back, as the controller's straight moves go: every point
    reached within 1 cm, no joint at a limit, back at the start the joints are where they
    began; a seed with the elbow turned away ends near home."""
    kin, home = panda.kinematics, np.array(panda.params.home_position)
    yaw = np.pi
    start = np.array([0.40, 0.0, 0.15])
    q = kin.grasp_ik(start, yaw, home)
    assert q is not None
    q0 = q.copy()
    path = [start + np.array([0.0, -0.3, -0.1]) * s for s in np.linspace(0, 1, 30)]
    for p in [*path, *path[::-1]]:
        q = kin.grasp_ik(p, yaw, q)
        assert q is not None, p
        assert np.linalg.norm(kin.tool_position(q) - p) < 0.01
        assert np.all(q > kin.lower + 0.01) and np.all(q < kin.upper - 0.01), q
    np.testing.assert_allclose(q, q0, atol=0.1)
    # from a seed with the elbow turned away from home (joints 3 and 5), the solution turns it
    # back: the null-space pull (plain damped least squares leaves joint 3 at 0.24 rad)
    seed = q0.copy()
    seed[2] += 0.6
    seed[4] -= 0.4
    q = kin.grasp_ik(start, yaw, seed)
    assert q is not None and abs(q[2] - home[2]) < 0.12 and abs(q[4] - home[4]) < 0.12, q
    # the null-space pull leaves the tool still: the solver meets its tolerances (0.2 mm,
    # 2 mrad) as a six-joint arm's does, not after all its iterations short of them
    _, ep, er = kin.solve(path[-1], kin.down_rotation(yaw), q0)
    assert ep < 2e-4 and er < 2e-3, (ep, er)


def test_the_null_space_step_leaves_the_tool_still() -> None:
    rng = np.random.default_rng(0)
    jac = rng.normal(size=(6, 7))
    lower, upper = -np.full(7, 2.0), np.full(7, 2.0)
    q, home = rng.uniform(-1.5, 1.5, 7), np.zeros(7)
    step = redundancy_step(jac, q, home, lower, upper)
    assert np.linalg.norm(step) > 0.1
    np.testing.assert_allclose(jac @ step, 0.0, atol=1e-12)
    # towards home: the step goes downhill on the distance to it
    assert step @ (home - q) > 0
    # six joints: no null space, nothing added
    assert not np.any(redundancy_step(jac[:, :6], q[:6], home[:6], lower[:6], upper[:6]))


def test_the_twist_input_moves_the_tool_and_never_moves_a_still_arm(panda: GraspFsm) -> None:
    kin = panda.kinematics
    q = np.array(panda.params.home_position) + 0.3
    posture = (q, np.array(panda.params.home_position), kin.lower, kin.upper)
    jac = kin.jacobian(q)
    twist = np.array([0.05, 0.0, -0.02, 0.0, 0.0, 0.1])
    v = velocities_from_twist(jac, twist[:3], twist[3:], posture=posture)
    np.testing.assert_allclose(jac @ v, twist, atol=2e-3)
    plain = velocities_from_twist(jac, twist[:3], twist[3:])
    assert not np.allclose(v, plain)     # the null-space pull towards home is in it
    assert not np.any(velocities_from_twist(jac, np.zeros(3), np.zeros(3), posture=posture))


@pytest.mark.parametrize('degrees', [168.0, -162.0, 130.0])
def test_a_grasp_behind_the_base_keeps_the_arm_facing_it(panda: GraspFsm, degrees: float) -> None:
    """Joint 1 faces the object and the elbow stays as at home: pulled to home too, joint 1
    swung back towards 0 and joints 3 and 5 turned half round to reach over the shoulder
    (4 of the 5 misses of a random-locations run were objects 158-168 deg behind the base)."""
    kin, home = panda.kinematics, np.array(panda.params.home_position)
    a = np.radians(degrees)
    seed = home.copy()
    seed[0] = np.clip(a, kin.lower[0] + 0.05, kin.upper[0] - 0.05)
    for z in (0.17, 0.03):
        q = kin.grasp_ik(np.array([0.63 * np.cos(a), 0.63 * np.sin(a), z]), a + np.pi, seed)
        assert q is not None
        assert abs(q[0] - seed[0]) < 0.1 and abs(q[2]) < 0.1 and abs(q[4]) < 0.1, q
        seed = q


def test_a_near_object_is_approached_with_the_tool_leaning_back(panda: GraspFsm) -> None:
    """Random locations seed 0 trial 19: a cube 0.20 m from the Panda's base axis. With the elbow
    at its limit no vertical pose exists 0.10 m above it (the trial ended 'no inverse-kinematics
    solution above the object', then an arm twisted round joint 1 that hit its own base); the
    pre-grasp leans the tool back towards the base, the descent keeps that lean."""
    kin, policy = panda.kinematics, panda.policy
    q = np.array([-2.306, -0.602, 0.001, -2.500, 0.001, 1.468, 0.786])   # entering state 4
    obj = np.array([-0.1396, -0.1485, 0.025])
    policy.begin_approach(0.0, 'cube', 0)
    policy.object_position = obj
    pre = policy._pregrasp_point()
    yaw = np.arctan2(obj[1], obj[0]) + np.pi
    assert kin.grasp_ik(pre, yaw, q) is None
    assert policy._plan_pregrasp(q) == ''
    q_pre = policy._q_target
    assert 0.0 < policy._tilt <= policy.params.max_approach_tilt
    np.testing.assert_allclose(kin.tool_position(q_pre), pre, atol=0.01)
    tool_z = (kin.link_pose(q_pre, kin.tool_link) @ kin._tool_offset)[:3, 2]
    radial = obj[:2] / np.linalg.norm(obj[:2])
    assert tool_z[2] < -0.8 and float(tool_z[:2] @ radial) < -0.1     # down, tip to the base
    # the same arm posture, turned to the object: joint 1 stays where it faces it
    assert abs(q_pre[0] - q[0]) < 0.1
    # every point of the straight descent to the grasp height has a pose at the same lean
    q_now = q_pre
    for z in np.linspace(pre[2], policy._grasp_z(), 12):
        q_now = kin.grasp_ik(np.array([obj[0], obj[1], z]), policy._yaw, q_now, policy._tilt)
        assert q_now is not None


def test_the_hand_turns_round_only_after_every_lean(panda: GraspFsm) -> None:
    """Seed 1 trial 55: vertical with the hand turned round, the Panda's IK found a pose
    twisted 0.8 rad about joint 1 whose link 5 hit link 1 on the way; leaning at the grasp
    yaw keeps the arm's posture, facing the object."""
    q = np.array([-2.21, -0.60, 0.0, -2.50, 0.0, 1.53, 0.78])
    panda.policy.begin_approach(0.0, 'cylinder', 0)
    panda.policy.object_position = np.array([-0.1458, -0.1880, 0.025])
    assert panda.policy._plan_pregrasp(q) == ''
    assert abs(panda.policy._q_target[0] - q[0]) < 0.1


def test_a_descent_without_a_pose_at_its_lean_leans_further(panda: GraspFsm) -> None:
    """Seed 1 trial 60: half way down to a near cylinder, the lean chosen above it (0.15 rad)
    had no pose (the elbow at its limit); the descent leans further instead of failing."""
    policy = panda.policy
    q = np.array([1.735, -0.559, -0.547, -3.132, -0.467, 2.437, 1.061])
    setpoint = np.array([0.04259, 0.22219, 0.10170])    # where the descent was
    policy.begin_approach(0.0, 'cylinder', 0)
    policy._yaw, policy._tilt = -1.7483, 0.15
    policy._line = (setpoint, setpoint, 0.0, 1.0)
    assert panda.kinematics.grasp_ik(setpoint, policy._yaw, q, 0.15, turn_round=False) is None
    _, _, failed = policy._follow_line(0.5, q)
    assert not failed and policy._tilt > 0.15
