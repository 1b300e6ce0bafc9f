"""robot:=xarm6: the simulator node loads the UFactory xArm6 description in its own process, over
real DDS: its joints at the description's home pose on /joint_states, and the joints follow
velocity commands on /arm_controller/commands."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_sim_node import Probe, spin_until, start

from mindgrasp_common.robot_description import load_robot

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(('robot', 'n_joints'), [('xarm6', 6), ('panda', 7)])
def test_the_arm_starts_at_home_and_follows_velocity_commands(rclpy_ctx, spawn_node, robot,
                                                              n_joints):
    """Also the seven-joint Panda (tests/sim/test_robot_panda.py): one velocity per joint."""
    arm = load_robot(robot)
    proc = start(spawn_node, f'robot:={robot}')
    assert f"with the robot '{robot}'" in proc.output()
    probe = Probe(rclpy_ctx)
    rclpy, node = rclpy_ctx, probe.node
    assert spin_until(rclpy, node, lambda: len(probe.joints) > 20, 120), proc.output()
    js = probe.joints[-1]
    assert list(js.name) == list(arm.arm_joints) and len(js.name) == n_joints
    np.testing.assert_allclose(probe.q(), arm.home_pose, atol=0.01)
    assert probe.matched(), proc.output()
    # base yaw and wrist roll (the last joint) move at the commanded rate, the others hold
    v = np.zeros(n_joints)
    v[0], v[-1] = 0.3, -0.4
    assert probe.drive(v, lambda: probe.q()[0] > arm.home_pose[0] + 0.3), proc.output()
    moving = probe.joints[-1]
    np.testing.assert_allclose(np.asarray(moving.velocity), v, atol=0.05)
    assert probe.q()[-1] < arm.home_pose[-1] - 0.3
    np.testing.assert_allclose(probe.q()[1:-1], arm.home_pose[1:-1], atol=0.01)
    proc.stop()


@pytest.mark.parametrize(('robot', 'atol'), [('xarm6', 0.02), ('panda', 0.002)])
def test_the_gripper_closes_on_command(rclpy_ctx, spawn_node, robot, atol):
    """/gripper_controller/commands [1.0] closes all six joints of the xArm's gripper linkage
    to the description's closed position (self_collision: false keeps its links from jamming
    each other half way), and both prismatic fingers of the Panda's hand (atol in rad and m);
    /gripper/joint_states names them."""
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

    xarm = load_robot(robot)
    proc = start(spawn_node, f'robot:={robot}')
    probe = Probe(rclpy_ctx)
    fingers: list = []
    probe.node.create_subscription(JointState, '/gripper/joint_states', fingers.append, 100)
    assert probe.matched(), proc.output()
    probe.grip_pub.publish(probe.Float64MultiArray(data=[1.0]))
    assert spin_until(rclpy_ctx, probe.node, lambda: bool(fingers) and np.allclose(
        fingers[-1].position, xarm.gripper.closed, atol=atol), 60), \
        (fingers[-1].position if fingers else None, proc.output())
    assert list(fingers[-1].name) == list(xarm.gripper.joints)
    proc.stop()


def test_xarm6_mounted_camera_and_tcp_are_frames_of_tf_static(rclpy_ctx, spawn_node):
    """The wrist camera mount and the TCP offset, which the xArm's URDF lacks, are on /tf_static,
    so viewers place the camera images (frame camera_color_optical_frame) on the arm."""
    from mindgrasp_ros.interfaces.tf2_msgs.msg import TFMessage

    from mindgrasp_ros.topics import TF_STATIC

    proc = start(spawn_node, 'robot:=xarm6')
    node = rclpy_ctx.node.Node('xarm_tf_probe')
    static: list = []
    node.create_subscription(TFMessage, TF_STATIC.name, static.append, TF_STATIC.qos)
    assert spin_until(rclpy_ctx, node, lambda: bool(static), 60), proc.output()
    frames = {t.child_frame_id: t for t in static[-1].transforms}
    cam, tcp = frames['camera_color_optical_frame'], frames['tcp']
    assert cam.header.frame_id == tcp.header.frame_id == 'xarm_gripper_base_link'
    v = cam.transform.translation
    np.testing.assert_allclose([v.x, v.y, v.z], [0.07, 0.0, 0.02], atol=1e-9)
    q = cam.transform.rotation
    np.testing.assert_allclose([q.x, q.y, q.z, q.w],
                               Rotation.from_euler('xyz', [0.0, 0.0, np.pi / 2]).as_quat(),
                               atol=1e-9)
    assert tcp.transform.translation.z == pytest.approx(0.152)
    node.destroy_node()
    proc.stop()


def test_urdf_importer_warnings_stay_off_stdout(capfd):
    """PyBullet warns about the xArm URDF's inertias from C; stdout stays the caller's (a
    command's --json line)."""
    from mindgrasp_sim.simulation import Simulation

    Simulation(robot='xarm6', n_objects=0).close()
    out, err = capfd.readouterr()
    assert 'Bad inertia' not in out and 'Bad inertia' in err


def test_unknown_robot_exits_with_one_line_naming_the_fix(spawn_node):
    proc = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'robot:=ur5')
    assert proc.wait(60) == 2
    out = proc.output()
    assert "No robot is named 'ur5'; use one of ['iiwa_franka_hand'," in out
    assert 'Traceback' not in out
