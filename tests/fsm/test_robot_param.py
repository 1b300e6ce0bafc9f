"""robot:=NAME on the controller: the description sets the fsm's robot parameters, and its
kinematics (TCP offset, wrist camera mount) agree with PyBullet's for the xArm6; in its own
process over real DDS the controller reads the simulated xArm6's joints."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mindgrasp_common.robot_description import RobotDescriptionError, load_robot
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_testing import spin_until


def test_the_description_sets_the_robot_parameters():
    xarm = load_robot('xarm6')
    p = FsmParams(robot='xarm6')
    assert p.joint_names == list(xarm.arm_joints) and p.home_position == list(xarm.home_pose)
    assert p.urdf_file == xarm.urdf_uri and p.tool_link == p.camera_link == \
        'xarm_gripper_base_link'
    assert p.joint_lower_limits == list(xarm.lower) and p.max_joint_velocity == [1.0, 1.0, 1.3,
                                                                                 1.3, 1.6, 1.6]
    # no robot: the parameters as given (the shipped arm's defaults)
    assert FsmParams().joint_names == [f'joint_{i}' for i in range(1, 7)]
    with pytest.raises(RobotDescriptionError, match="No robot is named 'ur5'"):
        FsmParams(robot='ur5')


def test_xarm6_kinematics_match_pybullet():
    from mindgrasp_sim.simulation import Simulation

    kin = GraspFsm.from_params(FsmParams(robot='xarm6')).kinematics
    sim = Simulation(robot='xarm6', n_objects=0)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = sim.home_pose + rng.uniform(-0.5, 0.5, 6)
        pos = sim.forward_kinematics(q, 'tcp')[0]
        np.testing.assert_allclose(kin.tool_position(q), pos, atol=1e-6)
        cam_pos, cam_quat = sim.forward_kinematics(q, 'camera')
        c_pos, c_rot = kin.camera_pose(q)
        np.testing.assert_allclose(c_pos, cam_pos, atol=1e-6)
        np.testing.assert_allclose(c_rot, Rotation.from_quat(cam_quat).as_matrix(), atol=1e-6)
    # the TCP (the middle of the finger pads) 0.152 m along the tool axis from the gripper base
    # at home (the simulated arm's gravity sag is a few um)
    base, quat = sim.link_pose('xarm_gripper_base_link')
    tcp = base + Rotation.from_quat(quat).as_matrix() @ [0, 0, 0.152]
    np.testing.assert_allclose(kin.tool_position(sim.home_pose), tcp, atol=1e-4)
    sim.close()


@pytest.mark.slow
def test_fsm_node_reads_the_simulated_xarm6(rclpy_ctx, spawn_node):
    """sim_node and fsm_node with robot:=xarm6, each its own process: the controller takes the
    xArm's /joint_states (never refused as the wrong size or broken; a loaded machine may let
    them go stale for a moment, which is not what this test is about), and stops for want of
    vision, not of joints."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState

    from mindgrasp_ros.topics import FSM_STATE

    sim = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'robot:=xarm6',
                     '-p', 'duration:=300.0')
    fsm = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'robot:=xarm6',
                     '-p', 'autonomous:=true', '-p', 'duration:=300.0')
    node = rclpy_ctx.node.Node('fsm_xarm_observer')
    states: list = []
    node.create_subscription(FsmState, FSM_STATE.name, states.append, FSM_STATE.qos)
    assert sim.wait_for_output("with the robot 'xarm6'", 120), sim.output()
    ok = spin_until(node, lambda: bool(states) and states[-1].stopped
                    and 'camera' in states[-1].reason, 120.0)
    assert ok, ([s.reason for s in states[-3:]], fsm.output()[-2000:], sim.output()[-1000:])
    refused = [s.reason for s in states if 'positions' in s.reason or 'NaN' in s.reason]
    assert not refused, refused
    node.destroy_node()
