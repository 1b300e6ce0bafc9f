"""The ``fsm`` node: the six-state MIndGrasp controller on ROS topics.

Run: ``python -m mindgrasp_fsm.fsm_node --ros-args --params-file config/param/fsm.yaml``

Subscribes ``/bci/prediction`` (mindgrasp_msgs/MIPrediction), ``/vision/detections``
(DetectionArray), ``/joint_states``, ``/gripper/joint_states`` + ``/gripper/contacts`` (finger
angles, efforts and contact flags), ``/camera/color/camera_info``. Publishes the arm
command in the form of ``command_interface`` (:mod:`mindgrasp_fsm.arm_output`):
``/arm_controller/commands`` (std_msgs/Float64MultiArray, one velocity per arm joint
in rad/s; default),
``/arm_controller/joint_trajectory`` (trajectory_msgs/JointTrajectory) or
``/servo_node/delta_twist_cmds`` (geometry_msgs/TwistStamped, after
``/servo_node/switch_command_type``);
``/gripper_controller/commands`` (``[closure]``, 0 open .. 1 closed) and ``/fsm/state``
(FsmState, transient local). The controller ticks when a prediction arrives, on a fresh joint
state once most of ``control_period`` has passed, and on its timer when neither came for 1.5
periods. Topic names and QoS: :mod:`mindgrasp_ros.topics`. Parameters: every
field of :class:`mindgrasp_fsm.params.FsmParams` (``mindgrasp param describe /fsm <name>`` shows
unit, range and whether a change applies live), plus ``duration`` (s; > 0 ends the node after
that time, for launch tests).
"""

from __future__ import annotations

import re
import time

import numpy as np
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, FsmState, MIPrediction
from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, JointState
from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray, UInt8MultiArray

from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import decoder_class_index
from mindgrasp_common.robot import DEFAULT_ROBOT
from mindgrasp_common.robot_description import load_robot
from mindgrasp_fsm.answer import readiness_problem
from mindgrasp_fsm.arm_output import ArmCommandOutput
from mindgrasp_fsm.conversions import gripper_from_fingers, vision_frame_from_msg
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.supervisor import SENSOR_FAULT
from mindgrasp_fsm.types import (
    STATE_NAMES,
    CameraModel,
    FsmInputs,
    FsmOutput,
    JointStateIn,
    Prediction,
    StopKind,
)
from mindgrasp_ros import rclpy
from mindgrasp_ros.graph_check import declare_graph_check, refuse_second_graph
from mindgrasp_ros.logs import log_at
from mindgrasp_ros.node_main import declare_duration, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import (
    ARM_COMMANDS,
    BCI_PREDICTION,
    COLOR_INFO,
    FSM_STATE,
    GRIPPER_COMMANDS,
    GRIPPER_CONTACTS,
    GRIPPER_JOINT_STATES,
    JOINT_STATES,
    VISION_DETECTIONS,
)

_NUMBER = re.compile(r'\d+(\.\d+)?')
#: a joint state makes the controller tick when this many control periods passed since its last
#: tick (0.75: every second state of a 100 Hz driver at the 50 Hz control rate)
_INPUT_TICK = 0.75
#: the timer ticks only when nothing else did for this many control periods
_TIMER_TICK = 1.5
#: a gap between ticks beyond this share of the watchdog timeout is a stall of this process
_OWN_STALL = 0.5


class FsmNode(rclpy.node.Node):
    """Thin ROS wrapper round :class:`GraspFsm` (parameters: config/param/fsm.yaml)."""

    node_traits = NodeTraits(   # --param values checked before a trial
        name='fsm', parameters=FsmParams,
        periodic={ARM_COMMANDS.name: ('control_period', 'period')})

    def __init__(self, **kwargs: object) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        # one FsmParams object, shared with the controller: live changes apply at the next tick
        self.params = declare_params(self, FsmParams)
        problem = readiness_problem(self.params)
        if problem:
            msg = f'The controller refuses to drive the arm: {problem}'
            raise FsmError(msg)
        started, graph_check_wait = time.monotonic(), declare_graph_check(self)
        self.fsm = GraspFsm.from_params(self.params)
        # open and closed positions (rad) of the gripper's first (driving) joint when the others
        # move with it over the same range (the shipped hand's fingers, the xArm's linkage),
        # else each joint's own (the Jaco hand's distal joints close less than its proximal)
        gripper = load_robot(self.params.robot or DEFAULT_ROBOT).gripper
        same = len(set(gripper.open)) == 1 and len(set(gripper.closed)) == 1
        self._gripper_range = ({'open_angle': gripper.open[0], 'closed_angle': gripper.closed[0]}
                               if same else {'open_angle': gripper.open,
                                             'closed_angle': gripper.closed})
        self.inputs = FsmInputs(time=0.0)
        self._fingers: np.ndarray | None = None
        self._finger_stamp = 0.0
        self._finger_efforts: np.ndarray | None = None
        self._contacts: np.ndarray | None = None
        self._last_state_msg: tuple | None = None
        self._last_state_pub = -1e9
        self.done = rclpy.task.Future()
        self.ticks = 0
        self._last_tick = -1e9      # s, node clock: when the controller last ticked
        self.own_stalls = 0         # ticks held because this process itself had stalled

        self.arm = ArmCommandOutput(self, self.params, self.fsm.kinematics)
        self.gripper_pub = self.create_publisher(Float64MultiArray, GRIPPER_COMMANDS.name,
                                                 GRIPPER_COMMANDS.qos)
        self.state_pub = self.create_publisher(FsmState, FSM_STATE.name, FSM_STATE.qos)
        self.create_subscription(MIPrediction, BCI_PREDICTION.name, self.prediction_callback,
                                 BCI_PREDICTION.qos)
        self.create_subscription(DetectionArray, VISION_DETECTIONS.name,
                                 self.detections_callback, VISION_DETECTIONS.qos)
        self.create_subscription(JointState, JOINT_STATES.name, self.joint_state_callback,
                                 JOINT_STATES.qos)
        self.create_subscription(JointState, GRIPPER_JOINT_STATES.name, self.finger_callback,
                                 GRIPPER_JOINT_STATES.qos)
        self.create_subscription(UInt8MultiArray, GRIPPER_CONTACTS.name, self.contacts_callback,
                                 GRIPPER_CONTACTS.qos)
        self.create_subscription(CameraInfo, COLOR_INFO.name, self.info_callback, COLOR_INFO.qos)
        self.create_timer(self.params.control_period, self.timer_callback)
        declare_duration(self)
        # a second /fsm or commander of the arm (another graph on this domain): refused before
        # the first command
        refuse_second_graph(self, FsmError, started=started, wait=graph_check_wait,
                            own_publishers={self.arm.topic: 1})
        mode = 'autonomous' if self.params.autonomous else 'BCI'
        if not self.params.autonomous and self.params.paradigm == 'scan':
            th = self.fsm.decision_thresholds()
            self.get_logger().info(
                f'Answer pair {self.fsm.answer.name} ({self.fsm.answer.describe()}); decision '
                f"thresholds confirm {th['confirm']:.2f}, pass {th['pass']:.2f}, affirm "
                f"{th['affirm']:.2f}, cancel {th['cancel']:.2f} nat s.")
        self.get_logger().info(f'Grasp controller ready ({mode} mode, arm commands on '
                               f'{self.arm.topic} ({self.arm.interface}), '
                               f'{1.0 / self.params.control_period:.0f} Hz, lock '
                               f'{self.params.lock_duration:.1f} s, watchdog '
                               f'{self.params.watchdog_timeout:.2f} s).')

    # ------------------------------------------------------------------ helpers
    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _stamp_or_now(self, header: object) -> float:
        t = rclpy.time.Time.from_msg(header.stamp).nanoseconds * 1e-9
        return t if t > 0 else self._now()   # unstamped messages: time of receipt

    # ------------------------------------------------------------------ callbacks
    def prediction_callback(self, msg: MIPrediction) -> None:
        probabilities = np.asarray(msg.probabilities, dtype=float)
        try:
            classes = tuple(decoder_class_index(n) for n in msg.class_names)
        except CommonError:
            classes = None                   # a decoder of classes the controller cannot use
        self.inputs.prediction = Prediction(
            int(msg.class_index), float(msg.certainty), self._stamp_or_now(msg.header),
            probabilities=probabilities if probabilities.size else None, classes=classes)
        self.control_callback()          # a decision reaches the arm at once, not at a tick

    def detections_callback(self, msg: DetectionArray) -> None:
        if msg.image_width == 0 or msg.image_height == 0:
            self.get_logger().error('Received /vision/detections with a zero image size; the '
                                    'vision node must fill image_width and image_height.',
                                    throttle_duration_sec=5.0)
            return
        self.inputs.vision = vision_frame_from_msg(msg, self._stamp_or_now(msg.header))

    def joint_state_callback(self, msg: JointState) -> None:
        """Keep a good joint state; a bad one is handed to the controller as a sensor fault
        (it latches a stop and says why), never used as a position."""
        names = list(msg.name)
        pos = np.asarray(msg.position, dtype=float)
        vel = np.asarray(msg.velocity, dtype=float)
        missing = [n for n in self.params.joint_names if n not in names]
        if missing:
            fault = (f'/joint_states names {names} lack the controller joints {missing}; set '
                     'joint_names to match the arm')
        elif pos.size != len(names) or vel.size not in (0, len(names)):
            fault = (f'/joint_states has {len(names)} names but {pos.size} positions and '
                     f'{vel.size} velocities; the arm driver must send one per joint')
        else:
            idx = [names.index(n) for n in self.params.joint_names]
            v = vel[idx] if vel.size else np.zeros(len(idx))
            if np.isfinite(pos[idx]).all() and np.isfinite(v).all():
                self.inputs.joints = JointStateIn(pos[idx], v, self._stamp_or_now(msg.header))
                # tick on the fresh state once a control period is nearly over (a 100 Hz
                # driver: every second state): the command starts from where the arm is
                if self._now() - self._last_tick >= _INPUT_TICK * self.params.control_period:
                    self.control_callback()
                return
            fault = 'joint states contain NaN or infinite values; check the arm driver'
        self.inputs.joint_fault = (self._now(), fault)

    def finger_callback(self, msg: JointState) -> None:
        self._fingers = np.asarray(msg.position, dtype=float)
        efforts = np.asarray(msg.effort, dtype=float)
        self._finger_efforts = efforts if efforts.size == self._fingers.size else None
        self._finger_stamp = self._stamp_or_now(msg.header)
        self._update_gripper()

    def contacts_callback(self, msg: UInt8MultiArray) -> None:
        self._contacts = np.asarray(msg.data, dtype=bool)
        self._update_gripper()

    def _update_gripper(self) -> None:
        if self._fingers is None or self._fingers.size == 0:
            return
        contacts = self._contacts if self._contacts is not None and \
            self._contacts.size == self._fingers.size else None
        self.inputs.gripper = gripper_from_fingers(self._fingers, self._finger_stamp, contacts,
                                                   self._finger_efforts, **self._gripper_range)

    def info_callback(self, msg: CameraInfo) -> None:
        k = np.asarray(msg.k, dtype=float)
        if k.size != 9 or k[0] <= 0 or k[4] <= 0 or msg.width == 0:
            self.get_logger().error(f'camera_info K {k.tolist()} is not a pinhole matrix '
                                    '(9 values, fx, fy > 0); check the camera driver.',
                                    throttle_duration_sec=5.0)
            return
        self.inputs.camera = CameraModel.from_k(int(msg.width), int(msg.height), k)

    def timer_callback(self) -> None:
        """The fallback tick: when no joint state or prediction made the controller tick for
        :data:`_TIMER_TICK` control periods (a silent driver, a stalled EEG), it ticks here, so
        the watchdog still stops the arm."""
        if self._now() - self._last_tick >= _TIMER_TICK * self.params.control_period:
            self.control_callback()

    def control_callback(self) -> None:
        """One controller tick: on a prediction, on a fresh joint state, or on the timer.

        A tick that comes :data:`_OWN_STALL` watchdog timeouts after the previous one (and two
        timer periods) follows a stall of this process (a busy machine): the inputs that arrived
        meanwhile still wait behind this callback, so their age says nothing yet. It holds the
        arm and judges at the next tick, instead of latching a sensor fault that only a fresh
        decision releases."""
        now = self._now()
        stall = max(_OWN_STALL * self.params.watchdog_timeout,
                    2 * _TIMER_TICK * self.params.control_period)
        if self.ticks and now - self._last_tick > stall:
            self._last_tick = now
            self.own_stalls += 1
            joints = self.inputs.joints
            self.arm.stop(None if joints is None else joints.position)
            return
        self._last_tick = now
        self.inputs.time = now
        out = self.fsm.tick(self.inputs)
        self.ticks += 1
        joints = self.inputs.joints
        self.arm.publish(out.joint_velocities, None if joints is None else joints.position)
        self.gripper_pub.publish(Float64MultiArray(data=np.array([out.gripper.position])))
        self._publish_state(out, now)
        for event in out.events:
            # a sensor fault's latch and release are the lines a user must see
            log_at(self.get_logger(), 'warning' if event.startswith(f'{SENSOR_FAULT}:') else
                   'info', f'State: {event}')

    def _publish_state(self, out: FsmOutput, now: float) -> None:
        """/fsm/state on every change, else at most once per second. A stop reason carries a
        changing age ("0.53 s old"): numbers do not count as a change, so a stopped controller
        says so once per second, not at the control rate."""
        reason = _NUMBER.sub('#', out.reason) if out.stopped else out.reason
        key = (int(out.state), out.locked, out.stopped, reason, out.object_of_interest,
               out.offered)
        if key == self._last_state_msg and now - self._last_state_pub < 1.0:
            return
        latched = any(e.startswith(f'{SENSOR_FAULT}:') for e in out.events)
        if out.stopped and not latched and (self._last_state_msg is None or
                                            not self._last_state_msg[2]):
            # a latch said why in its own line; waiting for a first input is how every start
            # begins (the nodes come up in any order): information, not a warning
            log_at(self.get_logger(), 'info' if out.stop_kind == StopKind.AWAITING_INPUT
                   else 'warning', out.reason)
        self._last_state_msg, self._last_state_pub = key, now
        msg = FsmState(state=int(out.state), state_name=STATE_NAMES[out.state],
                       previous_state=int(out.previous_state),
                       object_of_interest=out.object_of_interest, locked=bool(out.locked),
                       stopped=bool(out.stopped), reason=out.reason, paradigm=out.paradigm,
                       offered=bool(out.offered), confirm_evidence=float(out.confirm_evidence),
                       cancel_evidence=float(out.cancel_evidence),
                       answer_pair=self.fsm.answer.name,
                       yes_classes=list(self.fsm.answer.yes), no_classes=list(self.fsm.answer.no))
        msg.header.stamp = self.get_clock().now().to_msg()
        self.state_pub.publish(msg)

    def destroy_node(self) -> None:
        """Stop the arm (when the context still runs) and say how long the controller ran."""
        if rclpy.ok():
            joints = self.inputs.joints
            self.arm.stop(None if joints is None else joints.position)
        stalls = (f', {self.own_stalls} held after a stall of this process'
                  if self.own_stalls else '')
        self.get_logger().info(f'Controller ran {self.ticks} ticks{stalls}.')
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the controller until Ctrl-C or the ``duration`` parameter; arm stopped on exit."""
    return run_node(FsmNode, args, errors=(FsmError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
