"""The simulator's other two arm interfaces, beside ros2_control's forward velocity controller.

- ``/arm_controller/joint_trajectory`` (trajectory_msgs/JointTrajectory), as a ros2_control
  JointTrajectoryController streamed by a teleop driver: each message replaces the last one and
  the arm follows its first point (its velocities, or the way to its positions in its
  ``time_from_start``); an empty trajectory stops the arm.
- ``/servo_node/delta_twist_cmds`` (geometry_msgs/TwistStamped), as MoveIt Servo: the tool's
  linear (m/s) and angular (rad/s) velocity in the arm's base frame (``base_link``, or the world
  frame where the base stands), turned into joint velocities through the inverse of the arm's
  Jacobian. As in MoveIt Servo, twists move the arm only after ``/servo_node/switch_command_type``
  (moveit_msgs/srv/ServoCommandType) selected TWIST (1).

Both become joint velocities (n_joints,) rad/s that go through the node's one command path
(:meth:`SimNode.accept_arm_command`): the same command timeout (a stale driver input stops the
arm), velocity clipping, and refusal of bad commands with one warning per burst.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from mindgrasp_ros.interfaces.geometry_msgs.msg import TwistStamped
from mindgrasp_ros.interfaces.trajectory_msgs.msg import JointTrajectory

from mindgrasp_ros.topics import ARM_TRAJECTORY, SERVO_COMMAND_TYPE_SERVICE, SERVO_TWIST
from mindgrasp_sim.control import velocities_from_trajectory, velocities_from_twist
from mindgrasp_sim.errors import SimError

#: moveit_msgs/srv/ServoCommandType's command types (its constants; the message is imported only
#: where the service is offered, so a ROS 2 install without MoveIt runs the other inputs)
JOINT_JOG, TWIST, POSE = 0, 1, 2
_TYPE_NAMES = {JOINT_JOG: 'JOINT_JOG', TWIST: 'TWIST', POSE: 'POSE'}


class ArmCommandInputs:
    """Trajectory and servo-twist subscriptions and the servo's command-type service of one
    simulated arm (``io``: the node's ``_RobotIO``, namespaced by ``io.prefix``)."""

    def __init__(self, node: Any, io: Any) -> None:
        self.node, self.io = node, io
        self.servo_type = JOINT_JOG   # MoveIt Servo's type at start
        traj, twist = (t.in_namespace(io.prefix) for t in (ARM_TRAJECTORY, SERVO_TWIST))
        self.trajectory_topic, self.twist_topic = traj.name, twist.name
        node.create_subscription(JointTrajectory, traj.name, self.trajectory_callback, traj.qos)
        node.create_subscription(TwistStamped, twist.name, self.twist_callback, twist.qos)
        try:
            from mindgrasp_ros.interfaces.moveit_msgs.srv import ServoCommandType
        except ImportError:   # real rclpy without moveit_msgs: no twists, the rest works
            node.get_logger().info(f'{io.prefix}{SERVO_COMMAND_TYPE_SERVICE} is not offered: '
                                   'moveit_msgs is not installed (install ros-jazzy-moveit-msgs '
                                   'for servo_twist).')
            return
        node.create_service(ServoCommandType, f'{io.prefix}{SERVO_COMMAND_TYPE_SERVICE}',
                            self.switch_command_type_callback)

    def trajectory_callback(self, msg: JointTrajectory) -> None:
        sim, io = self.node.sim, self.io

        def velocities() -> np.ndarray:
            if not msg.points:
                return np.zeros(len(sim.joint_names))   # an empty trajectory stops the arm
            point = msg.points[0]
            t = point.time_from_start.sec + point.time_from_start.nanosec * 1e-9
            return velocities_from_trajectory(list(msg.joint_names), sim.joint_names,
                                              point.positions, point.velocities, t,
                                              sim.joint_positions(io.name))

        self.node.accept_arm_command(velocities, io, self.trajectory_topic)

    def twist_callback(self, msg: TwistStamped) -> None:
        sim, io = self.node.sim, self.io
        t = msg.twist
        linear = np.array([t.linear.x, t.linear.y, t.linear.z])
        angular = np.array([t.angular.x, t.angular.y, t.angular.z])
        if self.servo_type != TWIST:
            # MoveIt Servo ignores commands of a type it was not switched to
            moving = bool(np.any(linear) or np.any(angular))
            if moving and io.bursts.bad('servo_type', self.node.sim_now()):
                self.node.get_logger().warning(
                    f'Ignored {self.twist_topic}: the servo command type is '
                    f'{_TYPE_NAMES[self.servo_type]}; call '
                    f'{io.prefix}{SERVO_COMMAND_TYPE_SERVICE} with command_type 1 (TWIST) '
                    'first (one warning per burst).')
            return

        def velocities() -> np.ndarray:
            frames = ('', self.node.tf_tree.root, self.node.params.frame_id)
            if msg.header.frame_id not in frames:
                msg_ = (f'twist frame_id {msg.header.frame_id!r} is not the arm base frame; '
                        f'send twists in {self.node.tf_tree.root!r}.')
                raise SimError(msg_)
            q = sim.joint_positions(io.name)
            return velocities_from_twist(sim.tool_jacobian(q), linear, angular,
                                         posture=(q, sim.home_pose, sim.lower, sim.upper))

        self.node.accept_arm_command(velocities, io, self.twist_topic)

    def switch_command_type_callback(self, request: Any, response: Any) -> Any:
        """moveit_msgs/srv/ServoCommandType: select the command type (TWIST moves the arm)."""
        kind = int(request.command_type)
        response.success = kind in _TYPE_NAMES
        if response.success:
            self.servo_type = kind
            self.node.get_logger().info(f'Servo command type {_TYPE_NAMES[kind]} '
                                        f'({self.twist_topic} moves the arm: '
                                        f'{kind == TWIST}).')
        else:
            self.node.get_logger().warning(
                f'{self.io.prefix}{SERVO_COMMAND_TYPE_SERVICE}: command_type {kind} is not one '
                'of 0 (JOINT_JOG), 1 (TWIST), 2 (POSE).')
        return response


__all__ = ['ArmCommandInputs']
