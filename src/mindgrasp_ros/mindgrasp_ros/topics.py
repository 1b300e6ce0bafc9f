"""The graph's topics in one table: name, message type, QoS, who publishes and who reads.

Nodes and the recorder take names and QoS from here, so a publisher and its readers always agree
(DESIGN.md and the README's topic table are checked against :data:`TOPICS` by a test)::

    from mindgrasp_ros.topics import FSM_STATE, JOINT_STATES

    self.state_pub = self.create_publisher(FsmState, FSM_STATE.name, FSM_STATE.qos)
    self.create_subscription(JointState, JOINT_STATES.name, self.joint_state_callback,
                             JOINT_STATES.qos)

A namespaced copy of a contract (the training robot's arm under ``/trainer_robot``) is
``JOINT_STATES.in_namespace('/trainer_robot')``. Every name stays remappable with ``-r``.

Adding a topic: add a :class:`Topic` constant below and to :data:`TOPICS`, then regenerate the
README's table with ``python -m mindgrasp_ros.topics`` (the test prints the expected table).
"""

from __future__ import annotations

import dataclasses
import importlib
from typing import Any

__all__ = ['LATCHED_QUEUE', 'TOPICS', 'Qos', 'Topic', 'markdown_table', 'topic']


@dataclasses.dataclass(frozen=True)
class Qos:
    """A QoS in words; :attr:`Topic.qos` builds the active rclpy's ``QoSProfile`` from it."""

    reliability: str = 'reliable'        #: 'reliable' or 'best_effort'
    durability: str = 'volatile'         #: 'volatile' or 'transient_local' (latched)
    depth: int = 10                      #: KEEP_LAST depth

    def profile(self) -> Any:
        from mindgrasp_ros import rclpy

        q = rclpy.qos
        return q.QoSProfile(
            depth=self.depth, history=q.HistoryPolicy.KEEP_LAST,
            reliability=q.ReliabilityPolicy[self.reliability.upper()],
            durability=q.DurabilityPolicy[self.durability.upper()])

    def text(self) -> str:
        """For the README table: 'reliable, transient local, depth 1'."""
        parts = [self.reliability.replace('_', ' ')]
        if self.durability != 'volatile':
            parts.append(self.durability.replace('_', ' '))
        parts.append(f'depth {self.depth}')
        return ', '.join(parts)


RELIABLE = Qos()
LATCHED = Qos(durability='transient_local', depth=1)
#: a latched topic read or written with a queue of 10: a subscriber keeps the late-joiner sample
#: and what follows it; the virtual subjects' intent keeps its last 10 for a late recorder
LATCHED_QUEUE = Qos(durability='transient_local', depth=10)
SENSOR = Qos(reliability='best_effort', depth=5)      # rclpy's qos_profile_sensor_data


@dataclasses.dataclass(frozen=True)
class Topic:
    """One topic of the graph."""

    name: str           #: absolute default name
    type: str           #: 'pkg/msg/Name'
    qos_spec: Qos       #: the QoS every publisher and subscription uses
    source: str         #: who publishes
    readers: str        #: who reads
    note: str = ''      #: units, encoding

    @property
    def qos(self) -> Any:
        """The ``rclpy.qos.QoSProfile`` of this topic (real rclpy or our runtime)."""
        return self.qos_spec.profile()

    @property
    def msg_class(self) -> type:
        """The message class (from ``mindgrasp_ros.interfaces``)."""
        pkg, _, name = self.type.split('/')
        return getattr(importlib.import_module(f'mindgrasp_ros.interfaces.{pkg}.msg'), name)

    def in_namespace(self, namespace: str) -> Topic:
        """The same contract under ``namespace`` ('' or '/' keeps the name)."""
        ns = namespace.rstrip('/')
        return dataclasses.replace(self, name=f'{ns}{self.name}') if ns else self


def _t(name: str, type_: str, qos: Qos, source: str, readers: str, note: str = '') -> Topic:
    return Topic(name, type_, qos, source, readers, note)


EEG_RAW = _t('/eeg/raw', 'mindgrasp_msgs/msg/EEGChunk',
             Qos(reliability='best_effort', depth=100),
             'eeg_acquisition', 'classifier, recorder', 'volts')
EEG_STATUS = _t('/eeg/status', 'diagnostic_msgs/msg/DiagnosticArray', RELIABLE,
                'eeg_acquisition', 'all')
#: latched with a queue: a recorder that starts after the acquisition node still gets the
#: last 100 markers (a trigger sent at start-up is not lost)
EEG_MARKERS = _t('/eeg/markers', 'mindgrasp_msgs/msg/EEGMarker',
                 Qos(durability='transient_local', depth=100),
                 'eeg_acquisition (marker_stream)', 'recorder, export',
                 "the amplifier's LSL markers; stamp on the /eeg/raw clock")
BCI_PREDICTION = _t('/bci/prediction', 'mindgrasp_msgs/msg/MIPrediction', RELIABLE,
                    'classifier', 'fsm, vision, graz')
BCI_STATUS = _t('/bci/status', 'diagnostic_msgs/msg/DiagnosticArray', RELIABLE,
                'classifier', 'all')
TRAINER_PROMPT = _t('/trainer/prompt', 'mindgrasp_msgs/msg/Prompt', LATCHED,
                    'trainer, graz', 'classifier, virtual subject, recorder',
                    'a late reader gets the current phase only')
TRAINER_DISPLAY = _t('/trainer/display', 'sensor_msgs/msg/Image', SENSOR,
                     'trainer, graz', 'participant display', 'rgb8')
TRAINER_EE_DISTANCE = _t('/trainer/ee_distance', 'std_msgs/msg/Float64', RELIABLE,
                         'trainer', 'recorder', 'm')
COLOR_IMAGE = _t('/camera/color/image_raw', 'sensor_msgs/msg/Image', SENSOR,
                 'sim (or camera driver)', 'vision', 'rgb8')
DEPTH_IMAGE = _t('/camera/depth/image_raw', 'sensor_msgs/msg/Image', SENSOR,
                 'sim (or camera driver)', 'vision', '32FC1, metres')
COLOR_INFO = _t('/camera/color/camera_info', 'sensor_msgs/msg/CameraInfo', SENSOR,
                'sim (or camera driver)', 'vision, fsm')
DEPTH_INFO = _t('/camera/depth/camera_info', 'sensor_msgs/msg/CameraInfo', SENSOR,
                'sim (or camera driver)', 'vision')
JOINT_STATES = _t('/joint_states', 'sensor_msgs/msg/JointState', RELIABLE,
                  'sim (or arm driver)', 'fsm, virtual subject', 'rad, rad/s')
ARM_COMMANDS = _t('/arm_controller/commands', 'std_msgs/msg/Float64MultiArray', RELIABLE,
                  'fsm', 'sim (or arm driver)', 'one velocity per arm joint, rad/s')
ARM_TRAJECTORY = _t('/arm_controller/joint_trajectory', 'trajectory_msgs/msg/JointTrajectory',
                    RELIABLE, 'fsm (command_interface trajectory)',
                    'sim (or JointTrajectoryController)',
                    'streamed, 0.1 s ahead, header stamp 0 = start now')
SERVO_TWIST = _t('/servo_node/delta_twist_cmds', 'geometry_msgs/msg/TwistStamped', RELIABLE,
                 'fsm (command_interface servo_twist)', 'sim (or MoveIt Servo)',
                 'tool twist in base_link, m/s, rad/s')
#: MoveIt Servo's service that selects the command type (moveit_msgs/srv/ServoCommandType)
SERVO_COMMAND_TYPE_SERVICE = '/servo_node/switch_command_type'
GRIPPER_COMMANDS = _t('/gripper_controller/commands', 'std_msgs/msg/Float64MultiArray',
                      RELIABLE, 'fsm', 'sim (or arm driver)', '[closure], 0 open .. 1 closed')
GRIPPER_JOINT_STATES = _t('/gripper/joint_states', 'sensor_msgs/msg/JointState', RELIABLE,
                          'sim (or arm driver)', 'fsm', 'finger angles, rad')
GRIPPER_CONTACTS = _t('/gripper/contacts', 'std_msgs/msg/UInt8MultiArray', RELIABLE,
                      'sim (or arm driver)', 'fsm', '1 = finger touches')
EE_POSE = _t('/ee_pose', 'geometry_msgs/msg/PoseStamped', RELIABLE,
             'sim', 'trainer, viewers', 'm')
VISION_DETECTIONS = _t('/vision/detections', 'mindgrasp_msgs/msg/DetectionArray', RELIABLE,
                       'vision', 'fsm, display')
VISION_OVERLAY = _t('/vision/overlay', 'sensor_msgs/msg/Image', SENSOR,
                    'vision', 'display', 'rgb8')
FSM_STATE = _t('/fsm/state', 'mindgrasp_msgs/msg/FsmState', LATCHED,
               'fsm', 'all', 'on change, at most 1 Hz otherwise')
TASK_TARGET = _t('/task/target', 'mindgrasp_msgs/msg/TaskTarget', LATCHED,
                 'trial manager', 'sim, virtual subject, display')
TASK_RESULT = _t('/task/result', 'mindgrasp_msgs/msg/GraspResult', RELIABLE,
                 'sim', 'trial manager, recorder')
SIM_OBJECTS = _t('/sim/objects', 'visualization_msgs/msg/MarkerArray', LATCHED,
                 'sim', 'trial manager, virtual subject, viewers')
ROBOT_DESCRIPTION = _t('/robot_description', 'std_msgs/msg/String', LATCHED,
                       'sim (or robot_state_publisher)', 'viewers (RViz, Foxglove)', 'URDF')
TF = _t('/tf', 'tf2_msgs/msg/TFMessage', Qos(depth=100),
        'sim (or robot_state_publisher)', 'viewers',
        'arm and finger joints, 20 Hz (tf_publish_frequency) while subscribed')
TF_STATIC = _t('/tf_static', 'tf2_msgs/msg/TFMessage', LATCHED,
               'sim (or robot_state_publisher)', 'viewers', 'world->base_link, camera, TCP')
SIM_STATUS = _t('/sim/status', 'diagnostic_msgs/msg/DiagnosticArray', RELIABLE, 'sim', 'all')
VIRTUAL_SUBJECT_INTENT = _t('/virtual_subject/intent', 'std_msgs/msg/String', LATCHED,
                            'virtual amplifier', 'recorder', 'the imagined class')
SCENE_IMAGE = _t('/scene/image_raw', 'sensor_msgs/msg/Image', SENSOR,
                 'sim', 'participant display', 'rgb8, third-person view (scene_camera_rate > 0)')
DISPLAY_FLIP = _t('/display/flip', 'mindgrasp_msgs/msg/Prompt', Qos(depth=50),
                  'participant display', 'recorder, labels', 'stamp = when the phase was drawn')
DISPLAY_IMAGE = _t('/display/image', 'sensor_msgs/msg/Image', SENSOR,
                   'participant display (headless)', 'viewers', "rgb8, the participant's frame")
CLOCK = _t('/clock', 'rosgraph_msgs/msg/Clock', Qos(reliability='best_effort', depth=1),
           'sim (fast mode) or bag play', 'all')

#: The training robot: the arm contract under /trainer_robot (sim -> trainer, trainer -> sim).
TRAINER_ROBOT = '/trainer_robot'
TRAINER_ROBOT_TOPICS = tuple(
    dataclasses.replace(t.in_namespace(TRAINER_ROBOT), source=src, readers=dst)
    for t, src, dst in ((JOINT_STATES, 'sim', 'trainer'), (EE_POSE, 'sim', 'trainer'),
                        (ARM_COMMANDS, 'trainer', 'sim'),
                        (GRIPPER_COMMANDS, 'trainer', 'sim'),
                        (GRIPPER_JOINT_STATES, 'sim', 'trainer'),
                        (GRIPPER_CONTACTS, 'sim', 'trainer')))

#: Every topic of the graph, by name.
TOPICS: dict[str, Topic] = {t.name: t for t in (
    EEG_RAW, EEG_STATUS, EEG_MARKERS, BCI_PREDICTION, BCI_STATUS, TRAINER_PROMPT, TRAINER_DISPLAY,
    TRAINER_EE_DISTANCE, COLOR_IMAGE, DEPTH_IMAGE, COLOR_INFO, DEPTH_INFO, JOINT_STATES,
    ARM_COMMANDS, ARM_TRAJECTORY, SERVO_TWIST, GRIPPER_COMMANDS, GRIPPER_JOINT_STATES,
    GRIPPER_CONTACTS, EE_POSE,
    VISION_DETECTIONS, VISION_OVERLAY, FSM_STATE, TASK_TARGET, TASK_RESULT, SIM_OBJECTS,
    ROBOT_DESCRIPTION, TF, TF_STATIC, SIM_STATUS, VIRTUAL_SUBJECT_INTENT, SCENE_IMAGE,
    DISPLAY_FLIP, DISPLAY_IMAGE, CLOCK,
    *TRAINER_ROBOT_TOPICS)}


def topic(name: str) -> Topic:
    """The table's entry for ``name``; a clear error for a name that is not in the graph."""
    try:
        return TOPICS[name]
    except KeyError:
        msg = (f"'{name}' is not a topic of the graph; the topics are: "
               f'{", ".join(sorted(TOPICS))} (add new ones to mindgrasp_ros/topics.py).')
        raise KeyError(msg) from None


def markdown_table() -> str:
    """The README's topic table, one row per topic."""
    rows = ['| topic | type | from -> to | QoS | notes |', '|---|---|---|---|---|']
    for t in TOPICS.values():
        short = t.type.replace('/msg/', '/')
        rows.append(f'| {t.name} | {short} | {t.source} -> {t.readers} | {t.qos_spec.text()} '
                    f'| {t.note} |')
    return '\n'.join(rows)


if __name__ == '__main__':
    print(markdown_table())
