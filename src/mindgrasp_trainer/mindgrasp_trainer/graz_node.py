"""Graz-BCI prompter node: publishes the cue schedule on /trainer/prompt and draws the screen.

Run::

    python -m mindgrasp_trainer.graz_node --ros-args -p n_trials:=40 -p seed:=1 \
        --params-file src/mindgrasp_trainer/mindgrasp_trainer/param/trainer.yaml

Publishes ``/trainer/prompt`` (mindgrasp_msgs/Prompt, reliable, transient local, depth 1: a late
joiner gets the current phase) and ``/trainer/display`` (sensor_msgs/Image rgb8, when
``display_rate`` > 0); subscribes ``/bci/prediction`` for the feedback bar (hidden when the last
prediction is older than ``prediction_timeout`` s). Ends by itself after
the last trial, or after ``duration`` seconds when that is > 0.
"""

from __future__ import annotations

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import MIPrediction, Prompt
from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import run_node
from mindgrasp_ros.topics import BCI_PREDICTION, TRAINER_DISPLAY, TRAINER_PROMPT
from mindgrasp_trainer.display import render_display
from mindgrasp_trainer.graz import GrazProtocol, PromptSequencer
from mindgrasp_trainer.protocol import TrainerError
from mindgrasp_trainer.ros_common import (
    EegGate,
    check_rate,
    fixed_parameters_callback,
    to_msg,
)


class GrazNode(rclpy.node.Node):
    """Publishes the Graz-BCI schedule of :class:`GrazProtocol` as it unfolds in ROS time."""

    def __init__(self, **kwargs) -> None:
        super().__init__('graz_prompter', **kwargs)
        self.declare_parameters('', [
            ('n_trials', 40), ('classes', [0, 1, 2, 3]), ('seed', 0),
            ('fixation', 2.0), ('cue', 1.25), ('imagery', 2.75),
            ('rest_min', 1.5), ('rest_max', 2.5), ('max_repeat', 0),
            ('start_delay', 5.0), ('duration', 0.0), ('rate', 200.0),
            ('display_rate', 10.0), ('display_width', 480), ('display_height', 360),
            ('feedback', 'move'), ('max_certainty', 1.0), ('prediction_timeout', 1.0),
            ('wait_for_eeg', False),
        ])  # fmt: skip
        p = {name: self.get_parameter(name).value for name in (
            'n_trials', 'classes', 'seed', 'fixation', 'cue', 'imagery', 'rest_min', 'rest_max',
            'max_repeat', 'start_delay')}  # fmt: skip
        self.duration = float(self.get_parameter('duration').value)
        self.display = {
            'width': int(self.get_parameter('display_width').value),
            'height': int(self.get_parameter('display_height').value),
            'feedback': str(self.get_parameter('feedback').value),
            'max_certainty': float(self.get_parameter('max_certainty').value),
        }
        try:
            self.protocol = GrazProtocol(**p)
            self.sequencer = PromptSequencer(self.protocol.schedule())
            render_display(None, **self.display)  # validates the display parameters
            rate = check_rate('rate', self.get_parameter('rate').value)
            display_rate = check_rate(
                'display_rate', self.get_parameter('display_rate').value, allow_zero=True
            )
        except TrainerError as err:
            self.get_logger().error(str(err))
            raise
        self.n_trials = len(self.protocol.class_order())
        self.prediction: tuple[int, float] | None = None
        self.prediction_ns = 0  # ROS time of the latest prediction's arrival
        timeout = float(self.get_parameter('prediction_timeout').value)
        self.prediction_timeout_ns = int(timeout * 1e9)
        self.t0_ns: int | None = None
        self.done = rclpy.task.Future()  # result set when the session has ended
        # wait_for_eeg: the schedule starts once EEG flows (an amplifier that starts late on a
        # busy machine would otherwise miss the first trials)
        self.eeg_gate = EegGate(self) if self.get_parameter('wait_for_eeg').value else None

        self.prompt_pub = self.create_publisher(Prompt, TRAINER_PROMPT.name, TRAINER_PROMPT.qos)
        self.create_subscription(MIPrediction, BCI_PREDICTION.name, self.prediction_callback,
                                 BCI_PREDICTION.qos)
        self.create_timer(1.0 / rate, self.tick_callback)
        if display_rate > 0:
            self.display_pub = self.create_publisher(Image, TRAINER_DISPLAY.name,
                                                     TRAINER_DISPLAY.qos)
            self.create_timer(1.0 / display_rate, self.display_callback)
        self.add_on_set_parameters_callback(fixed_parameters_callback({
            'feedback': lambda v: self._set_display('feedback', str(v)),
            'max_certainty': lambda v: self._set_display('max_certainty', float(v)),
        }))  # fmt: skip
        self.get_logger().info(
            f'Graz-BCI session: {self.n_trials} trials, classes {list(self.protocol.classes)}, '
            f'seed {self.protocol.seed}, {self.protocol.total_duration():.1f} s planned.'
        )

    @property
    def finished(self) -> bool:
        return self.done.done()

    def _set_display(self, key: str, value: object) -> None:
        render_display(None, **(self.display | {key: value}))  # raises TrainerError if invalid
        self.display[key] = value

    def prediction_callback(self, msg: MIPrediction) -> None:
        self.prediction = (int(msg.class_index), float(msg.certainty))
        self.prediction_ns = self.get_clock().now().nanoseconds

    def tick_callback(self) -> None:
        if self.finished:
            return
        now = self.get_clock().now()
        if now.nanoseconds == 0:  # use_sim_time and no /clock yet
            return
        if self.t0_ns is None:
            if self.eeg_gate is not None and not self.eeg_gate.ready():
                return
            self.t0_ns = now.nanoseconds
        elapsed = (now.nanoseconds - self.t0_ns) * 1e-9
        events = self.sequencer.due(elapsed)
        if self.duration > 0 and elapsed >= self.duration and not self.sequencer.done:
            events.append(self.sequencer.stop(elapsed))
        for event in events:
            self.prompt_pub.publish(to_msg(event, now.to_msg()))
            late_ms = (elapsed - event.onset) * 1e3
            if event.phase == 'cue':
                self.get_logger().info(
                    f'Trial {event.trial}/{self.n_trials}: cue {event.class_name} '
                    f'(published {late_ms:.1f} ms after the planned onset).'
                )
            elif event.phase == 'end':
                self.get_logger().info(f'Graz-BCI session ended after {elapsed:.1f} s.')
                self.done.set_result(0)

    def display_callback(self) -> None:
        # a classifier that went quiet shows no bar rather than a stale one
        age_ns = self.get_clock().now().nanoseconds - self.prediction_ns
        prediction = self.prediction if age_ns <= self.prediction_timeout_ns else None
        frame = render_display(self.sequencer.current, prediction, **self.display)
        msg = Image(
            height=frame.shape[0], width=frame.shape[1], encoding='rgb8',
            is_bigendian=0, step=frame.shape[1] * 3, data=frame.reshape(-1),
        )  # fmt: skip
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = 'trainer_display'
        self.display_pub.publish(msg)


def main(args: list[str] | None = None) -> int:
    """Run the session until it ends (exit code of ``done``), Ctrl-C or a bad parameter (2); the
    last prompts get 0.5 s to reach reliable readers."""
    return run_node(GrazNode, args, errors=(TrainerError,), linger_sec=0.5)


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
