"""The simulator node's JointTrajectoryController and MoveIt Servo inputs in their own process,
over real DDS: bad commands refused with one line per burst (the arm holds), the servo's command
type switched by its service, and a silent driver input stopping the arm."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mindgrasp_testing import spin_until

pytestmark = pytest.mark.slow

JOINTS = [f'joint_{i}' for i in range(1, 7)]


@pytest.fixture
def sim(spawn_node, rclpy_ctx):
    """(node process, test node, joint states received)."""
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

    proc = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'duration:=300.0')
    assert proc.wait_for_output('Simulating scene', 120), proc.output()
    node = rclpy_ctx.node.Node('command_inputs_test')
    joints: list = []
    node.create_subscription(JointState, '/joint_states', joints.append, 100)
    assert spin_until(node, lambda: joints, 60.0)
    yield proc, node, joints
    node.destroy_node()


def _most_warnings(since: float, hold: float = 1.0) -> int:
    """The most "one warning per burst" lines a stream of bad commands sent since ``since``
    (time.monotonic(), s) can have given: a burst ends only after ``hold`` s without a bad
    command (the node's ``bad_command_hold``), so a new one needs that long of the stream's time
    (simulated time, which never runs ahead of the wall clock). On an idle machine that is 1; a
    loaded one may pause the stream and split it."""
    return 1 + int((time.monotonic() - since) / hold)


def _publish_at(node, rate: float, make) -> list[bool]:
    """Publish ``make()`` at ``rate`` Hz while the returned flag is True (while the test node
    spins)."""
    on = [True]
    node.create_timer(1.0 / rate, lambda: on[0] and make())
    return on


def test_trajectories_with_wrong_joints_are_refused_and_good_ones_followed(sim) -> None:
    from mindgrasp_ros.interfaces.trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

    proc, node, joints = sim
    pub = node.create_publisher(JointTrajectory, '/arm_controller/joint_trajectory', 10)
    names = [JOINTS]

    def trajectory() -> None:
        point = JointTrajectoryPoint(positions=np.zeros(6), velocities=np.array([0.3, 0, 0, 0, 0,
                                                                                 0]))
        point.time_from_start.nanosec = 50_000_000
        pub.publish(JointTrajectory(joint_names=names[0], points=[point]))

    names[0] = ['shoulder_pan', *JOINTS[1:]]
    bad_since = time.monotonic()
    sending = _publish_at(node, 50.0, trajectory)
    assert spin_until(node, lambda: 'Rejected /arm_controller/joint_trajectory' in proc.output(),
                      60.0), proc.output()
    n = len(joints)
    assert spin_until(node, lambda: len(joints) > n + 100, 60.0)   # 1 s of simulated time
    assert max(abs(m.velocity[0]) for m in joints[n:]) < 0.01
    line = [ln for ln in proc.output().splitlines() if 'Rejected' in ln]
    assert 1 <= len(line) <= _most_warnings(bad_since), line     # per burst, not per message
    assert ("JointTrajectory joint_names ['shoulder_pan', 'joint_2'" in line[0]
            and "send joint_names ['joint_1', 'joint_2'" in line[0]), line
    # the driver's names: after bad_command_hold (1 s) of good ones, the arm follows
    names[0] = JOINTS
    assert spin_until(node, lambda: joints[-1].velocity[0] > 0.25, 60.0), proc.output()[-2000:]
    sending[0] = False        # the stream ends: the command timeout stops the arm
    assert spin_until(node, lambda: abs(joints[-1].velocity[0]) < 0.01, 60.0)


def test_servo_twists_move_the_arm_after_the_switch_to_twist(sim) -> None:
    from mindgrasp_ros.interfaces.geometry_msgs.msg import PoseStamped, TwistStamped
    from mindgrasp_ros.interfaces.moveit_msgs.srv import ServoCommandType

    proc, node, joints = sim
    poses: list = []
    node.create_subscription(PoseStamped, '/ee_pose', poses.append, 100)
    pub = node.create_publisher(TwistStamped, '/servo_node/delta_twist_cmds', 10)
    frame = ['base_link']

    def twist() -> None:
        msg = TwistStamped()
        msg.header.frame_id = frame[0]
        msg.twist.linear.z = 0.05          # the tool straight up at 5 cm/s
        pub.publish(msg)

    ignored_since = time.monotonic()
    sending = _publish_at(node, 50.0, twist)
    # MoveIt Servo starts in JOINT_JOG: twists are ignored (one line) until it is switched
    assert spin_until(node, lambda: 'Ignored /servo_node/delta_twist_cmds' in proc.output(),
                      60.0), proc.output()
    n = len(joints)
    assert spin_until(node, lambda: len(joints) > n + 50, 60.0)
    assert max(abs(m.velocity[0]) for m in joints[n:]) < 0.01

    client = node.create_client(ServoCommandType, '/servo_node/switch_command_type')
    assert client.wait_for_service(timeout_sec=60.0)

    def call(kind: int) -> bool:
        future = client.call_async(ServoCommandType.Request(command_type=kind))
        assert spin_until(node, future.done, 60.0)
        return bool(future.result().success)

    assert not call(7)
    assert call(ServoCommandType.Request.TWIST)
    most_ignored = _most_warnings(ignored_since)
    # the tool rises straight up: 3 cm, while it keeps within 5 mm of its x and y
    start = np.array([poses[-1].pose.position.x, poses[-1].pose.position.y,
                      poses[-1].pose.position.z])

    def tool() -> np.ndarray:
        p = poses[-1].pose.position
        return np.array([p.x, p.y, p.z]) - start

    k = len(poses)
    assert spin_until(node, lambda: tool()[2] > 0.03, 60.0), (tool(), proc.output()[-2000:])
    drift = max(np.hypot(m.pose.position.x - start[0], m.pose.position.y - start[1])
                for m in poses[k:])
    assert drift < 0.005, drift
    # a twist in another frame is refused with the frame to use, and the arm holds
    frame[0] = 'camera_link'
    refused_since = time.monotonic()
    refused = "twist frame_id 'camera_link' is not the arm base frame; send twists in 'base_link'."
    assert spin_until(node, lambda: refused in proc.output(), 60.0), proc.output()
    assert spin_until(node, lambda: np.all(np.abs(joints[-1].velocity) < 0.01), 60.0)
    sending[0] = False
    out = proc.output()
    # one warning per burst of ignored, then of refused twists (not one per twist)
    assert 1 <= out.count('Ignored /servo_node/delta_twist_cmds') <= most_ignored, out
    assert 1 <= out.count('Rejected /servo_node/delta_twist_cmds') <= \
        _most_warnings(refused_since), out
