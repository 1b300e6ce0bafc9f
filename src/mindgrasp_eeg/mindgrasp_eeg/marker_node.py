"""LSL marker node: the session's events as an LSL marker stream, so LabRecorder records them in
one XDF with the amplifier's EEG.

    python -m mindgrasp_eeg.marker_node
    python -m mindgrasp_eeg.marker_node --ros-args -p cue_topic:=/display/flip

Outlet: ``stream_name`` (``MIndGrasp-Markers``), type ``Markers``, one string channel, irregular
rate, ``source_id`` ``mindgrasp-markers`` (stable, so a recorder finds it again after a restart).
Each marker is stamped with the ``pylsl.local_clock()`` time at which it happened: the message's
header stamp (ROS time) moved to the LSL clock, so a prompt is stamped with its onset (with
``cue_topic:=/display/flip``, the display's flip), not with when this node heard of it.

Markers (:mod:`mindgrasp_eeg.event_markers`, the same strings as the exports' annotations):

/trainer/prompt or /display/flip  ``prompt/<phase>/<class>``
/task/target                      ``target/<colour> <shape>``
/task/result                      ``result/success|failure/<object>`` (at the result)
/fsm/state                        ``state/<n> <name>`` on each change of state
"""

from __future__ import annotations

import pylsl
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, GraspResult, Prompt, TaskTarget

from mindgrasp_eeg import EEGError
from mindgrasp_eeg import event_markers as em
from mindgrasp_eeg.lsl import MarkerOutlet
from mindgrasp_eeg.params import MarkerParams
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import FSM_STATE, LATCHED_QUEUE, TASK_RESULT, TASK_TARGET


class MarkerNode(rclpy.node.Node):
    """Mirrors prompts, targets, results and controller states to an LSL marker outlet."""

    node_traits = NodeTraits(lockstep_left_out='LSL runs on wall time; the bag keeps the events')

    def __init__(self, **kwargs) -> None:
        super().__init__('lsl_markers', **kwargs)
        self.done = rclpy.task.Future()
        self.params = p = declare_params(self, MarkerParams)
        self.outlet = MarkerOutlet(p.stream_name, p.source_id)
        self.state: int | None = None
        self.count = 0
        latched = LATCHED_QUEUE.profile()     # no prompt or target is missed at start-up
        self.create_subscription(Prompt, p.cue_topic, self.prompt_callback, latched)
        self.create_subscription(TaskTarget, TASK_TARGET.name, self.target_callback, latched)
        self.create_subscription(GraspResult, TASK_RESULT.name, self.result_callback,
                                 TASK_RESULT.qos)
        self.create_subscription(FsmState, FSM_STATE.name, self.state_callback, latched)
        end_after(self, p.duration)
        self.get_logger().info(f"Markers on the LSL stream '{p.stream_name}' (type Markers, "
                               f"source_id '{p.source_id}'); cues from {p.cue_topic}.")

    def push(self, marker: str, stamp: object) -> None:
        """Push ``marker`` at the LSL time of ``stamp`` (a header stamp; now when unset)."""
        stamp_ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
        now_ns = self.get_clock().now().nanoseconds
        at = em.lsl_time(stamp_ns, now_ns, pylsl.local_clock()) if stamp_ns else 0.0
        self.outlet.push(marker, at)
        self.count += 1

    def prompt_callback(self, msg: Prompt) -> None:
        self.push(em.prompt_marker(msg.phase, msg.class_index), msg.header.stamp)

    def target_callback(self, msg: TaskTarget) -> None:
        self.push(em.target_marker(msg.colour, msg.shape), msg.header.stamp)

    def result_callback(self, msg: GraspResult) -> None:
        self.push(em.result_marker(msg.success, msg.desired_object), msg.header.stamp)

    def state_callback(self, msg: FsmState) -> None:
        if msg.state != self.state:       # /fsm/state repeats itself once a second
            self.state = int(msg.state)
            self.push(em.state_marker(msg.state, msg.state_name), msg.header.stamp)

    def destroy_node(self) -> None:
        """Say how many markers went out, then withdraw the stream."""
        self.get_logger().info(f'Sent {self.count} marker(s).')
        self.outlet.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run until Ctrl-C or ``duration``; exit 2 with one line on a bad parameter."""
    return run_node(MarkerNode, args, errors=(EEGError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)
