"""MIndGrasp Trainer node: the training robot prompts by moving; resets; end-effector distance.

Run (with the simulator's training robot up, e.g. ``mindgrasp launch trainer``)::

    python -m mindgrasp_trainer.trainer_node --ros-args -p n_trials:=40 -p seed:=1

Publishes ``/trainer/prompt`` (mindgrasp_msgs/Prompt, reliable, transient local, depth 1),
``/trainer_robot/arm_controller/commands`` (std_msgs/Float64MultiArray, joint velocities, rad/s)
and ``/trainer/ee_distance`` (std_msgs/Float64, m). Subscribes ``/trainer_robot/joint_states``,
``/trainer_robot/ee_pose``, ``/ee_pose`` and ``/fsm/state``; calls ``/sim/reset``
(mindgrasp_msgs/ResetSim) when the training end-effector goes below ``reset_height`` or the
user's controller enters the grasp state. Ends by itself after ``n_trials`` or ``duration`` s.
Every time it keeps (delays, ``robot_timeout``, ``reset_timeout``) is on the node's clock: the
wall clock in a live run, simulated time in lock-step (``mindgrasp launch trainer --lockstep``).
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass

import numpy as np
from mindgrasp_ros.interfaces.geometry_msgs.msg import PoseStamped
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, Prompt
from mindgrasp_ros.interfaces.mindgrasp_msgs.srv import ResetSim
from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
from mindgrasp_ros.interfaces.std_msgs.msg import Float64, Float64MultiArray

from mindgrasp_common.robot_description import RobotDescriptionError, load_robot, robot_choices
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params, param
from mindgrasp_ros.topics import (
    ARM_COMMANDS,
    EE_POSE,
    FSM_STATE,
    JOINT_STATES,
    TRAINER_EE_DISTANCE,
    TRAINER_PROMPT,
    TRAINER_ROBOT,
)
from mindgrasp_trainer.protocol import CLASS_NAMES, TrainerError, check_classes
from mindgrasp_trainer.ros_common import EegGate, to_msg
from mindgrasp_trainer.trainer import GRASP_OBJECT, TrainerProtocol, ee_distance

#: the TrainerProtocol arguments among the parameters
_PROTOCOL = ('n_trials', 'classes', 'seed', 'balanced', 'move_duration', 'wait_duration',
             'turn_speed', 'approach_speed', 'turn_joint', 'approach_joint', 'n_joints',
             'reset_height', 'grasp_state', 'settle_time', 'start_delay', 'duration')


@dataclass
class TrainerParams:
    """ROS parameters of the trainer (``trainer:`` in ``param/trainer.yaml``); only
    ``reset_timeout`` changes while it runs, the trials are planned at start."""

    n_trials: int = param(40, 'number of trials; the session ends after the last one', min=1,
                          max=100000)
    classes: list[int] = param([0, 1, 2, 3], 'classes to prompt: 0 left hand, 1 right hand, '
                               '2 both hands, 3 both feet')
    seed: int = param(0, 'seed of the class order', min=0)
    balanced: bool = param(True, 'balanced random order; false = independent draw per trial '
                           '(paper)')
    move_duration: float = param(2.0, 'training robot moves (paper: 2 s)', unit='s', min=0.001,
                                 max=3600.0)
    wait_duration: float = param(2.0, 'then waits for the user (paper: 2 s)', unit='s', min=0.0,
                                 max=3600.0)
    turn_speed: float = param(0.2, "velocity of 'turn_joint' for left hand (+) / right hand (-)",
                              unit='rad/s', min=-10.0, max=10.0)
    approach_speed: float = param(0.05, "velocity of 'approach_joint' for both hands (+, "
                                  'approach) / both feet (-, back away)', unit='rad/s',
                                  min=-10.0, max=10.0)
    turn_joint: int = param(0, 'zero-based joint turned for left/right hand (0: joint 1, base '
                            'yaw)', min=0, max=63)
    approach_joint: int = param(1, 'zero-based joint moved for both hands/feet (1: joint 2, '
                                'shoulder)', min=0, max=63)
    robot: str = param('mindgrasp_arm', "the training robot, a second copy of the user's arm "
                       f'(the same robot:= as the simulator): {robot_choices()}; the command '
                       'has one velocity per arm joint')
    reset_height: float = param(0.1, 'reset when the training end-effector goes below this',
                                unit='m', min=-10.0, max=10.0)
    grasp_state: int = param(GRASP_OBJECT, '... or when /fsm/state enters this state '
                             '(5 GRASP_OBJECT)', min=0, max=255)
    settle_time: float = param(1.0, 'rest after a reset before the next trial', unit='s',
                               min=0.0, max=3600.0)
    start_delay: float = param(5.0, 'after the training robot is heard from, before the first '
                               'trial', unit='s', min=0.0, max=3600.0)
    duration: float = param(0.0, 'end after this long even if trials remain (0 = run all '
                            'trials)', unit='s', min=0.0)
    rate: float = param(50.0, 'command and prompt timer; the simulator stops the arm after '
                        '0.25 s of silence', unit='Hz', min=1.0, max=10000.0)
    robot_timeout: float = param(30.0, 'give up when the training robot is not heard from '
                                 '(0 = wait forever)', unit='s', min=0.0)
    reset_timeout: float = param(5.0, '/sim/reset must answer within this', unit='s',
                                 min=0.001, max=3600.0, live=True)
    reset_new_random_draw: bool = param(False, 'a reset draws a new scene')
    log_file: str = param('', "per-trial CSV (distances in m); '' = log only")
    wait_for_eeg: bool = param(False, 'start the first trial once /eeg/raw flows (sessions '
                               'turn it on)')

    def __post_init__(self) -> None:
        check_classes(self.classes)
        # the length of the velocity command (n arm joints) comes from the robot's description
        self.n_joints = len(load_robot(self.robot).arm_joints)
        for name in ('turn_joint', 'approach_joint'):
            index = getattr(self, name)
            if not 0 <= index < self.n_joints:
                msg = (f"'{name}' is {index}, outside the {self.n_joints} arm joints of the "
                       f"robot {self.robot!r}; use an index from 0 to {self.n_joints - 1}.")
                raise TrainerError(msg)


def _position(msg: PoseStamped) -> np.ndarray:
    p = msg.pose.position
    return np.array([p.x, p.y, p.z], dtype=float)


class TrainerNode(rclpy.node.Node):
    """Runs :class:`TrainerProtocol` against the simulated training robot."""

    node_traits = NodeTraits(name='trainer', prompts=('trainer',), parameters=TrainerParams)

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.params = p = declare_params(self, TrainerParams)
        self.protocol = TrainerProtocol(**{name: getattr(p, name) for name in _PROTOCOL})
        self.trainer_pos: np.ndarray | None = None
        self.user_pos: np.ndarray | None = None
        self.fsm_state: int | None = None
        self.grasp_latch = False
        self.joint_count: int | None = None
        # times below are the node's clock in s (wall time live, simulated time in lock-step)
        self.reset_deadline: float | None = None  # by when /sim/reset must answer
        self.reset_future = None
        self.created: float | None = None  # first tick with a clock (sim time may start late)
        self.trainer_pose_time = math.inf  # arrival of the last training robot pose
        self.stale_warned = -math.inf
        self.done = rclpy.task.Future()  # result: exit code, set when the session has ended
        self.eeg_gate = EegGate(self) if p.wait_for_eeg else None

        self.prompt_pub = self.create_publisher(Prompt, TRAINER_PROMPT.name, TRAINER_PROMPT.qos)
        arm, joints, pose = (t.in_namespace(TRAINER_ROBOT)
                             for t in (ARM_COMMANDS, JOINT_STATES, EE_POSE))
        self.command_pub = self.create_publisher(Float64MultiArray, arm.name, arm.qos)
        self.distance_pub = self.create_publisher(Float64, TRAINER_EE_DISTANCE.name,
                                                  TRAINER_EE_DISTANCE.qos)
        self.create_subscription(JointState, joints.name, self.joint_states_callback, joints.qos)
        self.create_subscription(PoseStamped, pose.name, self.trainer_pose_callback, pose.qos)
        self.create_subscription(PoseStamped, EE_POSE.name, self.user_pose_callback, EE_POSE.qos)
        self.create_subscription(FsmState, FSM_STATE.name, self.fsm_callback, FSM_STATE.qos)
        self.reset_client = self.create_client(ResetSim, '/sim/reset')
        self.create_timer(1.0 / p.rate, self.tick_callback)
        self.get_logger().info(
            f'MIndGrasp Trainer: {self.protocol.n_trials} trials of '
            f'{self.protocol.move_duration} s move + {self.protocol.wait_duration} s wait, '
            f'seed {self.protocol.seed}; waiting for '
            '/trainer_robot/joint_states and /trainer_robot/ee_pose.'
        )

    @property
    def finished(self) -> bool:
        return self.done.done()

    @property
    def exit_code(self) -> int:
        return self.done.result() if self.done.done() else 0

    # ------------------------------------------------------------------ inputs
    def joint_states_callback(self, msg: JointState) -> None:
        self.joint_count = len(msg.position)

    def trainer_pose_callback(self, msg: PoseStamped) -> None:
        self.trainer_pos = _position(msg)
        self.trainer_pose_time = self._now()

    def user_pose_callback(self, msg: PoseStamped) -> None:
        self.user_pos = _position(msg)

    def fsm_callback(self, msg: FsmState) -> None:
        state = int(msg.state)
        # latch an entry into the grasp state until the next tick sees it, however short it was
        if state == self.protocol.grasp_state and self.fsm_state != state:
            self.grasp_latch = True
        self.fsm_state = state

    def _fsm_for_tick(self) -> int | None:
        if self.grasp_latch:
            self.grasp_latch = False
            return self.protocol.grasp_state
        return self.fsm_state

    # ------------------------------------------------------------------ loop
    def _now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _ready(self, t: float) -> bool:
        """True once the training robot is heard from; ends the node if it never is within
        ``robot_timeout`` of the first tick (``t``: the node's clock, s)."""
        if self.created is None:
            self.created = t
        if self.joint_count is not None and self.trainer_pos is not None:
            if self.eeg_gate is not None and not self.eeg_gate.ready():
                return False
            if self.joint_count != self.protocol.n_joints:
                self.get_logger().error(
                    f'/trainer_robot/joint_states has {self.joint_count} joints but the '
                    f'trainer commands the {self.protocol.n_joints} arm joints of the robot '
                    f"{self.params.robot!r}; start the simulator and the trainer with the same "
                    'robot:= (mindgrasp launch trainer robot:=NAME) or check the remapping.'
                )
                self._finish(1)
                return False
            return True
        if self.params.robot_timeout > 0 and t - self.created > self.params.robot_timeout:
            missing = [
                topic for topic, value in (
                    ('/trainer_robot/joint_states', self.joint_count),
                    ('/trainer_robot/ee_pose', self.trainer_pos),
                ) if value is None
            ]  # fmt: skip
            self.get_logger().error(
                f'No message on {" and ".join(missing)} within {self.params.robot_timeout:.1f} s: '
                'start the simulator with the training robot (mindgrasp launch trainer) or remap '
                "the topics; 'robot_timeout' sets the wait."
            )
            self._finish(1)
        return False

    def tick_callback(self) -> None:
        if self.finished:
            return
        now = self.get_clock().now()
        if now.nanoseconds == 0:  # use_sim_time and no /clock yet
            return
        t = now.nanoseconds * 1e-9
        if self.protocol.state == 'idle':
            if not self._ready(t):
                return
            events = self.protocol.start(t)
            step = self.protocol.update(t, self.trainer_pos[2], self._fsm_for_tick())
            step.events[:0] = events
        else:
            z = self.trainer_pos[2] if self.trainer_pos is not None else None
            step = self.protocol.update(t, z, self._fsm_for_tick())
        self._check_reset_timeout(t)
        self._check_stale_pose(t)
        if self.trainer_pos is not None and self.user_pos is not None:
            d = ee_distance(self.trainer_pos, self.user_pos)
            self.protocol.record_distance(d)
            self.distance_pub.publish(Float64(data=d))
        self.command_pub.publish(Float64MultiArray(data=step.command))
        for event in step.events:
            self.prompt_pub.publish(to_msg(event, now.to_msg()))
            if event.phase == 'move':
                self.get_logger().info(
                    f'Trial {event.trial}/{self.protocol.n_trials}: training robot shows '
                    f'{event.class_name}.'
                )
            elif event.phase == 'wait':
                tr = self.protocol.trial
                self.get_logger().info(
                    f'Trial {event.trial}: end-effector distance {tr.final_distance:.3f} m '
                    f'after the move (mean {tr.mean_distance:.3f} m).'
                )
        if step.reset:
            self._request_reset(step.reset, t)
        if step.done:
            self._finish(0)

    def _check_stale_pose(self, now: float) -> None:
        """Warn (every 5 s at most) when the training robot's pose stops arriving (``now``: the
        node's clock, s)."""
        age = now - self.trainer_pose_time
        if self.protocol.state in ('move', 'wait') and age > 1.0 and now - self.stale_warned > 5:
            self.stale_warned = now
            self.get_logger().warning(
                f'No /trainer_robot/ee_pose for {age:.1f} s: the reset rule and the distance '
                'metric use it. Is the simulator still running?'
            )

    def _request_reset(self, reason: str, t: float) -> None:
        self.get_logger().info(f'Resetting both robots: {reason}.')
        if not self.reset_client.service_is_ready():
            self.get_logger().error(
                'The reset service /sim/reset is not available, so the robots stay where they '
                'are: start the simulator (mindgrasp launch trainer) or remap /sim/reset.'
            )
            self.protocol.reset_finished(t, success=False)
            return
        request = ResetSim.Request(
            new_random_draw=self.params.reset_new_random_draw, seed=-1
        )
        self.reset_deadline = t + self.params.reset_timeout
        self.reset_future = self.reset_client.call_async(request)
        self.reset_future.add_done_callback(self.reset_done_callback)

    def reset_done_callback(self, future) -> None:
        if future is not self.reset_future:
            return  # an answer after its timeout
        self.reset_future = None
        self.reset_deadline = None
        try:
            response = future.result()
        except Exception as err:
            response = ResetSim.Response(success=False, message=repr(err))
        if not response.success:
            self.get_logger().error(f'/sim/reset failed: {response.message}')
        self.protocol.reset_finished(self._now(), success=bool(response.success))

    def _check_reset_timeout(self, t: float) -> None:
        if self.reset_deadline is not None and t > self.reset_deadline:
            self.get_logger().error(
                f'/sim/reset did not answer within {self.params.reset_timeout:.1f} s; the session '
                "goes on. Check the simulator's log, or raise 'reset_timeout'."
            )
            self.reset_future = None
            self.reset_deadline = None
            self.protocol.reset_finished(t, success=False)

    def _finish(self, code: int) -> None:
        if self.done.done():
            return
        self.done.set_result(code)
        self.command_pub.publish(Float64MultiArray(data=np.zeros(self.protocol.n_joints)))
        if code != 0 or not self.protocol.trials:
            return
        summary = json.dumps(_rounded(self.protocol.summary()))
        self.get_logger().info(f'Trainer session summary (distances in m): {summary}')
        if self.params.log_file:
            self._write_log(self.params.log_file)

    def _write_log(self, path: str) -> None:
        """Per-trial CSV: trial, class, onset (s), mean and final end-effector distance (m)."""
        try:
            with open(path, 'w', newline='', encoding='utf-8') as f:
                w = csv.writer(f)
                w.writerow(['trial', 'class_index', 'class_name', 'onset_s',
                            'mean_ee_distance_m', 'final_ee_distance_m', 'aborted'])  # fmt: skip
                for tr in self.protocol.trials:
                    w.writerow([tr.trial, tr.class_index, CLASS_NAMES[tr.class_index],
                                f'{tr.onset:.3f}', _fmt(tr.mean_distance),
                                _fmt(tr.final_distance), tr.aborted])  # fmt: skip
        except OSError as err:
            self.get_logger().error(
                f"Could not write the trial log 'log_file' = {path!r}: {err}. Give a writable path."
            )
            return
        self.get_logger().info(f'Trial log written to {path}.')

    def destroy_node(self) -> None:
        """The training robot stops when the node ends (also on Ctrl-C)."""
        if rclpy.ok():
            self.command_pub.publish(Float64MultiArray(data=np.zeros(self.protocol.n_joints)))
        super().destroy_node()


def _rounded(value: object) -> object:
    """Floats to 4 decimals (0.1 mm), recursively, for a readable log line."""
    if isinstance(value, float):
        return round(value, 4) if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    return value


def _fmt(x: float) -> str:
    return f'{x:.4f}' if math.isfinite(x) else ''


def main(args: list[str] | None = None) -> int:
    """Run the session until it ends (exit code of ``done``), Ctrl-C or a bad parameter (2); the
    last prompts get 0.5 s to reach reliable readers."""
    return run_node(TrainerNode, args, errors=(TrainerError, RobotDescriptionError),
                    linger_sec=0.5)


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
