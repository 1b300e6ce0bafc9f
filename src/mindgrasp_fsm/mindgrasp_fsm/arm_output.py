"""The fsm node's arm command publisher, one per ``command_interface`` (ROS plumbing only).

The forms are computed by :mod:`mindgrasp_fsm.command_interface`; this class owns the publisher
(and, for MoveIt Servo, the ``/servo_node/switch_command_type`` client) of the selected one:

- ``velocity``: std_msgs/Float64MultiArray on ``/arm_controller/commands``;
- ``trajectory``: trajectory_msgs/JointTrajectory on ``/arm_controller/joint_trajectory``;
- ``servo_twist``: geometry_msgs/TwistStamped on ``/servo_node/delta_twist_cmds``, after asking
  MoveIt Servo for TWIST commands each time its service appears.
"""

from __future__ import annotations

import numpy as np
from mindgrasp_ros.interfaces.builtin_interfaces.msg import Duration
from mindgrasp_ros.interfaces.geometry_msgs.msg import TwistStamped
from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray
from mindgrasp_ros.interfaces.trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from mindgrasp_fsm.command_interface import (
    HasJacobian,
    check_command_interface,
    trajectory_command,
    twist_command,
)
from mindgrasp_fsm.params import FsmParams
from mindgrasp_ros.topics import (
    ARM_COMMANDS,
    ARM_TRAJECTORY,
    SERVO_COMMAND_TYPE_SERVICE,
    SERVO_TWIST,
)


def _duration(seconds: float) -> Duration:
    ns = round(seconds * 1e9)
    return Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


class ArmCommandOutput:
    """Publishes the controller's joint velocities in the form ``params.command_interface``."""

    def __init__(self, node: object, params: FsmParams, kinematics: HasJacobian | None) -> None:
        self.node = node
        self.interface = check_command_interface(params.command_interface)
        self.params = params
        self.kinematics = kinematics
        self._servo_client = None
        self._servo_asked = False
        self._servo_future = None
        if self.interface == 'velocity':
            self.pub = node.create_publisher(Float64MultiArray, ARM_COMMANDS.name, ARM_COMMANDS.qos)
        elif self.interface == 'trajectory':
            self.pub = node.create_publisher(JointTrajectory, ARM_TRAJECTORY.name,
                                             ARM_TRAJECTORY.qos)
        else:
            # imported here: a ROS 2 install without MoveIt (moveit_msgs) runs the other two
            from mindgrasp_ros.interfaces.moveit_msgs.srv import ServoCommandType

            self._servo_request = ServoCommandType.Request(
                command_type=ServoCommandType.Request.TWIST)
            self.pub = node.create_publisher(TwistStamped, SERVO_TWIST.name, SERVO_TWIST.qos)
            self._servo_client = node.create_client(ServoCommandType, SERVO_COMMAND_TYPE_SERVICE)

    @property
    def topic(self) -> str:
        """The topic the commands go to."""
        return {'velocity': ARM_COMMANDS, 'trajectory': ARM_TRAJECTORY,
                'servo_twist': SERVO_TWIST}[self.interface].name

    def publish(self, velocities: np.ndarray, q: np.ndarray | None) -> None:
        """Send joint velocities (6,) rad/s given the current joints ``q`` (6,) rad (None before
        the first joint state: a trajectory or twist needs them, so only zero is sent then)."""
        v = np.asarray(velocities, dtype=float)
        if self.interface == 'velocity':
            self.pub.publish(Float64MultiArray(data=v))
            return
        if q is None:
            return      # no joint state yet: the driver's own timeout keeps the arm still
        if self.interface == 'trajectory':
            self.pub.publish(self._trajectory(q, v))
        else:
            self._switch_servo()
            self.pub.publish(self._twist(q, v))

    def _trajectory(self, q: np.ndarray, v: np.ndarray) -> JointTrajectory:
        n_points = max(2, round(self.params.trajectory_horizon / self.params.control_period))
        cmd = trajectory_command(q, v, self.params.trajectory_horizon, n_points)
        # header stamp 0: a JointTrajectoryController starts it at once (replacing the last one)
        return JointTrajectory(
            joint_names=list(self.params.joint_names),
            points=[JointTrajectoryPoint(positions=p, velocities=pv, time_from_start=_duration(t))
                    for t, p, pv in zip(cmd.times, cmd.positions, cmd.velocities, strict=True)])

    def _twist(self, q: np.ndarray, v: np.ndarray) -> TwistStamped:
        msg = TwistStamped()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = self.params.servo_frame
        if self.kinematics is not None and np.any(v):
            linear, angular = twist_command(self.kinematics, q, v)
            t = msg.twist
            t.linear.x, t.linear.y, t.linear.z = (float(x) for x in linear)
            t.angular.x, t.angular.y, t.angular.z = (float(x) for x in angular)
        return msg

    def _switch_servo(self) -> None:
        """Ask MoveIt Servo for TWIST commands whenever its service (re)appears."""
        if not self._servo_client.service_is_ready():
            self._servo_asked = False           # asked again when a (restarted) servo appears
            return
        if not self._servo_asked:
            self._servo_asked = True
            self._servo_future = self._servo_client.call_async(self._servo_request)
        if self._servo_future is not None and self._servo_future.done():
            result = self._servo_future.result()
            self._servo_future = None
            log = self.node.get_logger()
            if result is not None and result.success:
                log.info(f'MoveIt Servo takes twists on {SERVO_TWIST.name} (command type TWIST).')
            else:
                log.warning(f'{SERVO_COMMAND_TYPE_SERVICE} refused TWIST; the arm will not move '
                            'until MoveIt Servo accepts twist commands (check its config).')

    def stop(self, q: np.ndarray | None) -> None:
        """Send a zero command (the arm at rest where it is)."""
        self.publish(np.zeros(len(self.params.joint_names)), q)


__all__ = ['ArmCommandOutput']
