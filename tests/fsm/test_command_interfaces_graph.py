"""Each arm command interface end to end over real DDS: fsm_node and sim_node in their own
processes, the controller's joint velocities sent as std_msgs/Float64MultiArray (forward velocity
controller), trajectory_msgs/JointTrajectory (JointTrajectoryController) or
geometry_msgs/TwistStamped (MoveIt Servo, after /servo_node/switch_command_type), and the
simulated arm following them; stale inputs stop it through every interface."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_testing import spin_until

from .conftest import publish_left_hand

pytestmark = pytest.mark.slow

JOINTS = [f'joint_{i}' for i in range(1, 7)]
ACCELERATION = 2.0      # rad/s^2, max_joint_acceleration of param/fsm.yaml
PERIOD = 0.02           # s, control_period


def _joint_1_velocity(interface: str, msg: object) -> float:
    """Joint 1's commanded velocity (rad/s) in a command of ``interface``; checks its form."""
    if interface == 'velocity':
        return float(msg.data[0])
    if interface == 'trajectory':
        assert list(msg.joint_names) == JOINTS
        assert len(msg.points) >= 2 and msg.points[0].time_from_start.nanosec > 0
        return float(msg.points[0].velocities[0])
    assert msg.header.frame_id == 'base_link'
    # joint 1 turns the arm about the base's vertical axis: alone, it is the twist's angular z
    return float(msg.twist.angular.z)


@pytest.mark.parametrize(('interface', 'topic', 'type_name'), [
    ('velocity', '/arm_controller/commands', 'std_msgs/msg/Float64MultiArray'),
    ('trajectory', '/arm_controller/joint_trajectory', 'trajectory_msgs/msg/JointTrajectory'),
    ('servo_twist', '/servo_node/delta_twist_cmds', 'geometry_msgs/msg/TwistStamped'),
])
def test_the_arm_follows_each_interface_and_stops_when_inputs_go_stale(
        rclpy_ctx, spawn_node, interface: str, topic: str, type_name: str) -> None:
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, MIPrediction
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

    from mindgrasp_ros.typesupport import get_message_class

    sim = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'duration:=300.0')
    fsm = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'duration:=300.0',
                     '-p', 'paradigm:=paper', '-p', 'search_gain:=0.4', '-p', 'lock_duration:=0.5',
                     '-p', f'command_interface:={interface}')
    assert fsm.wait_for_output(f'arm commands on {topic} ({interface})', 60.0), fsm.output()
    node = rclpy.node.Node('command_interface_test')
    joints: list = []
    commands: list[float] = []
    node.create_subscription(JointState, '/joint_states', joints.append, 100)
    node.create_subscription(get_message_class(type_name), topic,
                             lambda m: commands.append(_joint_1_velocity(interface, m)), 100)
    det_pub = node.create_publisher(DetectionArray, '/vision/detections', 10)
    pred_pub = node.create_publisher(MIPrediction, '/bci/prediction', 10)
    sending = [True]

    node.create_timer(0.05, lambda: publish_left_hand(node, det_pub, pred_pub, sending[0]))
    # left-hand imagery turns joint 1 at search_gain (0.4 rad/s): the simulated arm follows
    assert spin_until(node, lambda: joints and joints[-1].velocity[0] > 0.35, 120.0), (
        commands[-3:], fsm.output()[-2000:], sim.output()[-2000:])
    others = np.abs(np.asarray(joints[-1].velocity)[1:])
    assert np.all(others < 0.05), others
    # the acceleration limit acts before the conversion: joint 1 ramps up tick by tick
    ramp = np.diff(commands[:commands.index(max(commands)) + 1])
    assert np.all(ramp <= ACCELERATION * PERIOD + 1e-9), ramp
    assert sum(0 < c < 0.4 - 1e-9 for c in commands) >= 5, commands[:20]
    # the predictions stop: the watchdog stops the controller, whose zero command (a resting
    # trajectory, a zero twist) stops the arm
    sending[0] = False
    assert spin_until(node, lambda: commands[-1] == 0.0 and abs(joints[-1].velocity[0]) < 0.01,
                      60.0), (commands[-3:], joints[-1].velocity)
    n = len(commands)
    assert spin_until(node, lambda: len(commands) > n + 10, 60.0)
    assert all(c == 0.0 for c in commands[n:])
    if interface == 'servo_twist':
        assert 'Servo command type TWIST' in sim.output(), sim.output()
        assert fsm.wait_for_output('MoveIt Servo takes twists', 60.0), fsm.output()
    assert 'Rejected' not in sim.output(), sim.output()
    node.destroy_node()
