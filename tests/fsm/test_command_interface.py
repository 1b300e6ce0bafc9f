"""The arm command forms of the controller (ROS-free): trajectory points, the tool twist through
the URDF Jacobian, and the one-line error for an unknown interface; the simulator's inverse of
each (mindgrasp_sim.control) gives back the joint velocities the controller computed."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_fsm.command_interface import (
    COMMAND_INTERFACES,
    check_command_interface,
    trajectory_command,
    twist_command,
)
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_sim.control import velocities_from_trajectory, velocities_from_twist

JOINTS = [f'joint_{i}' for i in range(1, 7)]
Q = np.array([0.1, 0.2, -0.3, 1.5, 1.1, 0.2])
V = np.array([0.3, -0.1, 0.05, 0.0, 0.2, -0.4])


def test_trajectory_points_run_ahead_from_the_current_joints() -> None:
    cmd = trajectory_command(Q, V, horizon=0.1, n_points=5)
    np.testing.assert_allclose(cmd.times, [0.02, 0.04, 0.06, 0.08, 0.1])
    np.testing.assert_allclose(cmd.positions, Q + cmd.times[:, None] * V)
    np.testing.assert_allclose(cmd.velocities, np.tile(V, (5, 1)))
    # a stop is a trajectory that holds the joints at rest
    stop = trajectory_command(Q, np.zeros(6))
    np.testing.assert_allclose(stop.positions, np.tile(Q, (2, 1)))
    assert not np.any(stop.velocities)


@pytest.mark.parametrize('use_velocities', [True, False])
def test_the_simulator_follows_the_trajectory_in_any_joint_order(use_velocities: bool) -> None:
    cmd = trajectory_command(Q, V, horizon=0.1, n_points=5)
    order = [5, 0, 3, 1, 4, 2]          # a driver may list the joints in its own order
    names = [JOINTS[i] for i in order]
    v = velocities_from_trajectory(names, JOINTS, cmd.positions[0][order],
                                   cmd.velocities[0][order] if use_velocities else [],
                                   cmd.times[0], Q)
    np.testing.assert_allclose(v, V, atol=1e-12)


@pytest.mark.parametrize(('names', 'positions', 'velocities', 't', 'message'), [
    (['a', 'b', 'c', 'd', 'e', 'f'], [0.0] * 6, [], 0.1,
     r"JointTrajectory joint_names \['a', 'b', .*\] are not the arm joints; send joint_names "
     r"\['joint_1', .*\] \(any order\)\."),
    (JOINTS[:5], [0.0] * 5, [], 0.1, 'are not the arm joints'),
    (JOINTS, [0.0] * 6, [0.1] * 5, 0.1, 'has 5 velocities for 6 joint_names'),
    (JOINTS, [0.0] * 4, [], 0.1, 'has 4 positions for 6 joint_names'),
    (JOINTS, [0.0] * 6, [], 0.0, 'time_from_start 0.0 s; give it a time > 0 s or velocities'),
    (JOINTS, [0.0] * 6, [float('nan')] * 6, 0.1, 'contains NaN or inf'),
])
def test_bad_trajectories_are_refused_with_the_fix(names, positions, velocities, t, message):
    from mindgrasp_sim.errors import SimError

    with pytest.raises(SimError, match=message):
        velocities_from_trajectory(names, JOINTS, positions, velocities, t, Q)


def test_the_twist_is_the_jacobian_times_the_velocities_and_the_simulator_inverts_it() -> None:
    kin = GraspFsm.from_params(FsmParams()).kinematics
    linear, angular = twist_command(kin, Q, V)
    # finite differences of the tool pose: the twist is the tool's velocity
    dt = 1e-6
    p0, p1 = kin.tool_position(Q), kin.tool_position(Q + V * dt)
    np.testing.assert_allclose(linear, (p1 - p0) / dt, atol=1e-5)
    # joint 1 turns about the base's vertical axis: alone, it is the twist's angular z
    _, ang1 = twist_command(kin, Q, [0.4, 0, 0, 0, 0, 0])
    np.testing.assert_allclose(ang1, [0, 0, 0.4], atol=1e-12)
    # the shipped arm's joints 2-5 turn about parallel axes: one self-motion leaves the tool
    # still, so the inverse gives the tool the same twist (and joint 1 its exact velocity)
    jac = kin.jacobian(Q)
    back = velocities_from_twist(jac, linear, angular, damping=1e-6)
    np.testing.assert_allclose(jac @ back, jac @ V, atol=1e-6)
    np.testing.assert_allclose(velocities_from_twist(jac, *twist_command(kin, Q, [0.4, 0, 0, 0,
                                                                                  0, 0])),
                               [0.4, 0, 0, 0, 0, 0], atol=1e-3)
    assert not np.any(velocities_from_twist(kin.jacobian(Q), np.zeros(3), np.zeros(3)))


def test_an_unknown_interface_is_one_line_naming_the_choices() -> None:
    assert all(check_command_interface(c) == c for c in COMMAND_INTERFACES)
    with pytest.raises(FsmError, match=r"command_interface is 'joint_jog'; use one of velocity, "
                                       r'trajectory, servo_twist \(e\.g\. '
                                       r'command_interface:=trajectory\)\.'):
        check_command_interface('joint_jog')
    with pytest.raises(FsmError, match="command_interface is 'twist'"):
        FsmParams(command_interface='twist').validate()
