"""Virtual amplifier node: synthetic EEG of a virtual subject as an LSL stream (or on /eeg/raw).

    python -m mindgrasp_eeg.virtual_amp_node --ros-args -p subject_mode:=follow -p seed:=3
    python -m mindgrasp_eeg.virtual_amp_node --ros-args -p output:=ros -p use_sim_time:=true

``output:=lsl`` (default, live runs): the LSL outlet (``stream_name``, 32 g.Nautilus channels at
250 Hz in microvolts by default) lives in this process, like an amplifier app; the acquisition
node reads it as any other amplifier. ``output:=ros`` (lock-step experiments): LSL runs on wall
time, so the node publishes ``/eeg/raw`` (mindgrasp_msgs/EEGChunk, volts, sensor-data QoS depth
100) itself, each chunk stamped with the node-clock time of its first sample, and no acquisition
node is needed.
The stream's ``source_id`` is the parameter's (the launch profiles give one made per run), else
``<stream_name>@<run directory name>`` in a launch, the stream name outside one: the profiles
pin their acquisition node to it, so two demos with the same stream name (other ROS domains,
other rigs on the network) never hear each other's amplifier.
Subscriptions depend on ``subject_mode``: ``follow`` listens to ``/trainer/prompt``; ``pursue`` to
``/task/target``, ``/sim/objects``, ``/joint_states`` and ``/fsm/state``; ``noise`` to nothing.
Samples are paced by the node clock: wall time, or ``/clock`` with ``use_sim_time``. The imagined
class is published on ``/virtual_subject/intent`` (std_msgs/String, on change) and as an LSL
marker on ``<stream_name>-markers``, as ground truth for evaluations.
"""

from __future__ import annotations

import numpy as np
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, FsmState, Prompt, TaskTarget
from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
from mindgrasp_ros.interfaces.std_msgs.msg import String
from mindgrasp_ros.interfaces.visualization_msgs.msg import MarkerArray

from mindgrasp_common.markers import objects_from_markers
from mindgrasp_common.robot_description import RobotDescriptionError
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.lsl import EEGOutlet, MarkerOutlet
from mindgrasp_eeg.montage import class_name
from mindgrasp_eeg.params import VirtualAmpParams
from mindgrasp_eeg.replay_eeg import ReplayEEG
from mindgrasp_eeg.ros_conversions import base_yaw_from_joint_state, ns_to_time_fields, time_to_s
from mindgrasp_eeg.subject import VirtualSubject, subject_heading
from mindgrasp_eeg.synthetic import SyntheticEEG
from mindgrasp_eeg.virtual_amp import VirtualAmplifier, run_source_id
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import (
    EEG_RAW,
    FSM_STATE,
    JOINT_STATES,
    LATCHED_QUEUE,
    SIM_OBJECTS,
    TASK_TARGET,
    TRAINER_PROMPT,
    VIRTUAL_SUBJECT_INTENT,
)


class VirtualAmpNode(rclpy.node.Node):
    """Feeds the virtual subject from ROS topics and paces the virtual amplifier."""

    # in lock-step there is no LSL (wall time): it publishes /eeg/raw itself
    node_traits = NodeTraits(name='virtual_amp', seed_parameters=('seed',),
                             lockstep_parameters={'output': 'ros'}, provides=('eeg',),
                             virtual_subject=True)

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.done = rclpy.task.Future()
        self.params = p = declare_params(self, VirtualAmpParams)
        if p.eeg_source != 'synthetic':
            gen = self.make_generator(p.eeg_source, p.seed)
        else:
            gen = SyntheticEEG(
                list(p.channel_names), p.sample_rate, seed=p.seed, head_seed=p.head_seed,
                background_rms=p.background_rms, alpha_rms=p.alpha_rms, mu_rms=p.mu_rms,
                beta_rms=p.beta_rms, sensor_noise_rms=p.sensor_noise_rms,
                erd_depth=p.erd_depth, erd_tau=p.erd_tau, blink_rate=p.blink_rate,
                blink_amplitude=p.blink_amplitude, emg_rate=p.emg_rate, emg_rms=p.emg_rms,
                line_noise=p.line_noise, line_freq=p.line_freq, separability=p.separability,
                lateral_separability=p.lateral_separability,
                rest_separability=p.rest_separability, nonstationarity=p.nonstationarity)
        # the stream's layout: the parameters', or the recordings' with a replay eeg_source
        self.channel_names = list(gen.channel_names)
        self.sample_rate = float(gen.sample_rate)
        self.subject = VirtualSubject(
            p.subject_mode, accuracy=p.accuracy, reaction_delay=p.reaction_delay,
            lapse_rate=p.lapse_rate, seed=p.seed, active_phases=p.active_phases,
            decision_period=p.decision_period, heading_tolerance=p.heading_tolerance)
        self.heading = subject_heading(p.robot, p.base_joint)
        latched = LATCHED_QUEUE.profile()
        mode = p.subject_mode
        if mode == 'follow':
            self.create_subscription(Prompt, TRAINER_PROMPT.name, self.prompt_callback, latched)
        elif mode == 'pursue':
            self.create_subscription(TaskTarget, TASK_TARGET.name, self.target_callback, latched)
            self.create_subscription(MarkerArray, SIM_OBJECTS.name, self.objects_callback,
                                     latched)
            self.create_subscription(JointState, JOINT_STATES.name, self.joints_callback,
                                     rclpy.qos.qos_profile_sensor_data)
            self.create_subscription(FsmState, FSM_STATE.name, self.fsm_callback, latched)
        self.pub_intent = self.create_publisher(String, VIRTUAL_SUBJECT_INTENT.name, latched)
        outlet, self.markers, self.pub_raw = None, None, None
        self.source_id = ''
        if p.output == 'ros':
            self.pub_raw = self.create_publisher(EEGChunk, EEG_RAW.name, EEG_RAW.qos)
        else:
            # the outlets last, so streaming starts soon after the stream becomes visible
            self.source_id = p.source_id or run_source_id(p.stream_name)
            outlet = EEGOutlet(p.stream_name, self.channel_names, self.sample_rate,
                               stream_type=p.stream_type, source_id=self.source_id, unit=p.unit,
                               reference=p.reference)
            self.markers = MarkerOutlet(f'{p.stream_name}-markers', f'{self.source_id}-markers')
        sim_time = bool(self.get_parameter('use_sim_time').value)
        self.amp = VirtualAmplifier(gen, self.subject, outlet, realtime_stamps=not sim_time,
                                    block=p.block, max_catch_up=1.0 if sim_time else None)
        self.sim_time = sim_time
        self._last_intent: object = 'unset'
        self.create_timer(p.push_period, self.push_callback)
        end_after(self, p.duration)
        where = (f"LSL stream '{p.stream_name}' (source_id {self.source_id!r})"
                 if outlet is not None else '/eeg/raw')
        self.get_logger().info(
            f'Virtual amplifier on {where}: {len(self.channel_names)} channels at '
            f'{self.sample_rate:g} Hz, subject mode {mode!r}, seed {p.seed}, '
            f"paced by {'/clock' if sim_time else 'wall time'}.")

    @staticmethod
    def make_generator(eeg_source: str, seed: int) -> ReplayEEG:
        """``eeg_source:=eegmmidb:<subject>`` or ``eeg_source:=path/to/subject.yaml``: real EEG of
        that replay subject's play recordings (their channels and rate replace channel_names and
        sample_rate; :mod:`mindgrasp_eeg.subject_file`)."""
        return ReplayEEG.from_source(eeg_source, seed=seed)

    def now_s(self) -> float:
        """Node clock (s): wall time, or simulated time with use_sim_time."""
        return self.get_clock().now().nanoseconds * 1e-9

    def prompt_callback(self, msg: Prompt) -> None:
        """A trainer prompt: the subject reacts from its onset (header stamp, else arrival)."""
        t = time_to_s(msg.header.stamp) or self.now_s()
        self.subject.on_prompt(t, int(msg.class_index), msg.phase, int(msg.trial))

    def target_callback(self, msg: TaskTarget) -> None:
        """The desired object."""
        self.subject.set_target(int(msg.object_id), msg.colour, msg.shape)

    def objects_callback(self, msg: MarkerArray) -> None:
        """Scene objects (world frame, base at ``base_position``)."""
        self.subject.set_objects(objects_from_markers(msg.markers, self.params.base_position))

    def joints_callback(self, msg: JointState) -> None:
        """Arm heading from the base joint."""
        angle = base_yaw_from_joint_state(msg.name, msg.position, self.heading.joint)
        if angle is not None:
            self.subject.set_base_yaw(self.heading(angle) + self.params.heading_offset)

    def fsm_callback(self, msg: FsmState) -> None:
        """Controller state and its object of interest."""
        self.subject.set_fsm(int(msg.state), msg.object_of_interest, msg.stopped,
                             paradigm=msg.paradigm, offered=msg.offered,
                             yes_classes=list(msg.yes_classes), no_classes=list(msg.no_classes))

    def push_callback(self) -> None:
        """Generate and push every sample due by now; report imagery changes."""
        now = self.now_s()
        if self.sim_time and now <= 0.0:
            return                                   # no /clock yet
        first = self.amp.n_samples
        data = self.amp.step(now)
        if self.pub_raw is not None and len(data):
            self.publish_chunk(data, first)
        if self.amp.current_class != self._last_intent:
            self._last_intent = self.amp.current_class
            name = class_name(self.amp.current_class)
            if self.markers is not None:
                self.markers.push(name)
            self.pub_intent.publish(String(data=name))

    def publish_chunk(self, data: np.ndarray, first: int) -> None:
        """``output:=ros``: one EEGChunk of ``data`` (n_samples, n_channels; volts) whose first
        sample is sample ``first`` of the stream, stamped on the node clock."""
        fs = self.sample_rate
        stamp_ns = round((self.amp.t_start + first / fs) * 1e9)
        msg = EEGChunk(sample_rate=fs, channel_names=self.channel_names,
                       n_samples=len(data), first_sample_index=first, unit='V',
                       data=np.ascontiguousarray(data, dtype=np.float32).ravel())
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_time_fields(stamp_ns)
        msg.header.frame_id = self.params.frame_id
        self.pub_raw.publish(msg)

    def destroy_node(self) -> None:
        """Withdraw the LSL streams, then the node."""
        if self.amp.outlet is not None:
            self.amp.outlet.close()
        if self.markers is not None:
            self.markers.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run until Ctrl-C or ``duration``; exit 2 with one line on a bad parameter."""
    return run_node(VirtualAmpNode, args, errors=(EEGError, RobotDescriptionError))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
