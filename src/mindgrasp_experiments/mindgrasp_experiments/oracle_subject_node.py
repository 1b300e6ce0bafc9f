"""The oracle subject: a perfect decoder of a competent user, publishing ``/bci/prediction``.

    python -m mindgrasp_experiments.oracle_subject_node --ros-args -p use_sim_time:=true

No EEG and no classifier: the virtual subject in pursue mode (:class:`~mindgrasp_eeg.subject.
VirtualSubject`, accuracy 1) decides what to imagine from ``/task/target``, ``/sim/objects``,
``/joint_states`` and ``/fsm/state``, and that class is published every ``period`` seconds as an
MIPrediction with ``certainty`` and probability ``probability`` (the decoder classes include
rest). While the subject rests, it publishes rest with certainty 0 (no command: the controller
acts on its own or waits). The upper bound of what the controller achieves with a BCI.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, MIPrediction, TaskTarget
from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
from mindgrasp_ros.interfaces.std_msgs.msg import String
from mindgrasp_ros.interfaces.visualization_msgs.msg import MarkerArray

from mindgrasp_common.markers import objects_from_markers
from mindgrasp_common.mi import DECODER_CLASS_NAMES, REST
from mindgrasp_common.robot_description import RobotDescriptionError
from mindgrasp_eeg.montage import class_name
from mindgrasp_eeg.ros_conversions import base_yaw_from_joint_state
from mindgrasp_eeg.subject import VirtualSubject, subject_heading
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params, param
from mindgrasp_ros.topics import (
    BCI_PREDICTION,
    FSM_STATE,
    JOINT_STATES,
    LATCHED_QUEUE,
    SIM_OBJECTS,
    TASK_TARGET,
    VIRTUAL_SUBJECT_INTENT,
)


@dataclass
class OracleParams:
    """Parameters of the oracle subject."""

    period: float = param(1.0 / 16.0, 'time between predictions', unit='s', min=1e-3)
    # 0.2: the default decoder's mean certainty on the virtual subject (records' mean_certainty),
    # so the arm moves as fast as with real decoding and the controller's gains fit both
    certainty: float = param(0.2, 'certainty of the intended class', min=0.0)
    probability: float = param(0.9, 'probability of the intended class (rest while the subject '
                               'rests)', min=0.0, max=1.0)
    reaction_delay: float = param(0.3, 'from a decision to its prediction', unit='s', min=0.0)
    decision_period: float = param(0.25, 'time between decisions', unit='s', min=1e-3)
    heading_tolerance: float = param(0.1, 'heading error taken as centred', unit='rad',
                                     min=0.0)
    robot: str = param('', "the arm (robot:= of the launch): its first joint, turning direction "
                       "and home give the heading; '' = the first joint's angle is the heading")
    seed: int = param(0, 'seed of the subject', min=0)
    duration: float = param(0.0, 'end after this long (0 = until stopped)', unit='s', min=0.0)


class OracleSubjectNode(rclpy.node.Node):
    """Publishes the pursuing subject's intended class as the prediction."""

    node_traits = NodeTraits(seed_parameters=('seed',))

    def __init__(self, **kwargs) -> None:
        super().__init__('oracle_subject', **kwargs)
        self.done = rclpy.task.Future()
        self.params = p = declare_params(self, OracleParams)
        self.subject = VirtualSubject('pursue', accuracy=1.0,
                                      reaction_delay=p.reaction_delay, seed=p.seed,
                                      decision_period=p.decision_period,
                                      heading_tolerance=p.heading_tolerance)
        self.heading = subject_heading(p.robot)
        latched = LATCHED_QUEUE.profile()
        self.create_subscription(TaskTarget, TASK_TARGET.name, self.target_callback, latched)
        self.create_subscription(MarkerArray, SIM_OBJECTS.name, self.objects_callback, latched)
        self.create_subscription(JointState, JOINT_STATES.name, self.joints_callback,
                                 rclpy.qos.qos_profile_sensor_data)
        self.create_subscription(FsmState, FSM_STATE.name, self.fsm_callback, latched)
        self.pub = self.create_publisher(MIPrediction, BCI_PREDICTION.name, BCI_PREDICTION.qos)
        self.pub_intent = self.create_publisher(String, VIRTUAL_SUBJECT_INTENT.name, latched)
        self._last_intent: object = 'unset'
        self.create_timer(p.period, self.predict_callback)
        end_after(self, p.duration)

    def now_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def target_callback(self, msg: TaskTarget) -> None:
        self.subject.set_target(int(msg.object_id), msg.colour, msg.shape)

    def objects_callback(self, msg: MarkerArray) -> None:
        self.subject.set_objects(objects_from_markers(msg.markers))

    def joints_callback(self, msg: JointState) -> None:
        angle = base_yaw_from_joint_state(msg.name, msg.position, self.heading.joint)
        if angle is not None:
            self.subject.set_base_yaw(self.heading(angle))

    def fsm_callback(self, msg: FsmState) -> None:
        self.subject.set_fsm(int(msg.state), msg.object_of_interest, msg.stopped,
                             paradigm=msg.paradigm, offered=msg.offered,
                             yes_classes=list(msg.yes_classes), no_classes=list(msg.no_classes))

    def predict_callback(self) -> None:
        now = self.now_s()
        if now <= 0.0:
            return                                    # no /clock yet
        intent = self.subject.intent(now)
        cls = REST if intent is None else int(intent)
        certainty = 0.0 if intent is None else self.params.certainty
        distances = np.full(len(DECODER_CLASS_NAMES), 1.0 + certainty, dtype=np.float32)
        distances[cls] = 1.0
        # the intended class (rest included) with p = oracle_probability, the rest shared
        others = (1.0 - self.params.probability) / (len(DECODER_CLASS_NAMES) - 1)
        probabilities = np.full(len(DECODER_CLASS_NAMES), others, dtype=np.float32)
        probabilities[cls] = self.params.probability
        msg = MIPrediction(class_index=cls, class_names=list(DECODER_CLASS_NAMES),
                           certainty=float(certainty), distances=distances, window_length=0.0,
                           probabilities=probabilities)
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub.publish(msg)
        if intent != self._last_intent:
            self._last_intent = intent
            self.pub_intent.publish(String(data=class_name(intent)))


def main(args: list[str] | None = None) -> int:
    """Run until Ctrl-C or ``duration``; exit 2 with one line on a robot that does not load."""
    return run_node(OracleSubjectNode, args, errors=(RobotDescriptionError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
