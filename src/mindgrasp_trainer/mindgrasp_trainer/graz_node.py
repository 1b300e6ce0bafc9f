"""Graz-BCI prompter node: publishes the cue schedule on /trainer/prompt and draws the screen.

Run::

    python -m mindgrasp_trainer.graz_node --ros-args -p n_trials:=40 -p seed:=1 \
        --params-file config/param/trainer.yaml

Publishes ``/trainer/prompt`` (mindgrasp_msgs/Prompt, reliable, transient local, depth 1: a late
joiner gets the current phase) and ``/trainer/display`` (sensor_msgs/Image rgb8, when
``display_rate`` > 0); subscribes ``/bci/prediction`` for the feedback bar (hidden when the last
prediction is older than ``prediction_timeout`` s). Ends by itself after
the last trial, or after ``duration`` seconds when that is > 0.
"""

from __future__ import annotations

from dataclasses import dataclass

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import MIPrediction, Prompt
from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

from mindgrasp_ros import rclpy
from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_ros.node_main import run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params, param
from mindgrasp_ros.topics import BCI_PREDICTION, TRAINER_DISPLAY, TRAINER_PROMPT
from mindgrasp_trainer.display import FEEDBACK_MODES, render_display
from mindgrasp_trainer.graz import GrazProtocol, PromptSequencer
from mindgrasp_trainer.protocol import TrainerError, check_classes
from mindgrasp_trainer.ros_common import EegGate, to_msg

#: the GrazProtocol arguments among the parameters
_PROTOCOL = ('n_trials', 'classes', 'seed', 'max_repeat', 'fixation', 'cue', 'imagery',
             'rest_min', 'rest_max', 'start_delay')


@dataclass
class GrazParams:
    """ROS parameters of the Graz prompter (``graz_prompter:`` in ``param/trainer.yaml``); only
    the feedback bar's settings change while it runs, the schedule is planned at start."""

    n_trials: int = param(40, 'total trials; a multiple of len(classes) gives exact balance',
                          min=1, max=100000)
    classes: list[int] = param([0, 1, 2, 3], 'classes to cue: 0 left hand, 1 right hand, '
                               '2 both hands, 3 both feet')
    seed: int = param(0, 'seed of the class order and the rest durations', min=0)
    max_repeat: int = param(0, 'longest run of one class in a row (0 = no limit)', min=0)
    fixation: float = param(2.0, 'fixation cross before the cue', unit='s', min=0.001,
                            max=3600.0)
    cue: float = param(1.25, 'arrow on screen', unit='s', min=0.001, max=3600.0)
    imagery: float = param(2.75, 'imagery after the arrow (cue + imagery = 4 s, BCI IV 2a)',
                           unit='s', min=0.001, max=3600.0)
    rest_min: float = param(1.5, 'shortest inter-trial rest', unit='s', min=0.0, max=3600.0)
    rest_max: float = param(2.5, 'longest inter-trial rest', unit='s', min=0.0, max=3600.0)
    start_delay: float = param(5.0, 'before the first fixation: amplifier, recorder and '
                               'subscribers come up', unit='s', min=0.0, max=3600.0)
    duration: float = param(0.0, 'end after this long even if trials remain (0 = no limit)',
                            unit='s', min=0.0)
    rate: float = param(200.0, 'prompt timer (onset resolution 1 / rate)', unit='Hz', min=1.0,
                        max=10000.0)
    display_rate: float = param(10.0, 'frames per second on /trainer/display (0 = no display '
                                'topic)', unit='Hz', min=0.0, max=10000.0)
    display_width: int = param(480, 'width of the /trainer/display frames', unit='px', min=32,
                               max=7680)
    display_height: int = param(360, 'height of the /trainer/display frames', unit='px',
                                min=32, max=4320)
    feedback: str = param('move', 'when the feedback bar from /bci/prediction shows',
                          choices=FEEDBACK_MODES, live=True)
    max_certainty: float = param(1.0, 'certainty that fills the feedback bar', min=1e-6,
                                 max=1e6, live=True)
    prediction_timeout: float = param(1.0, 'hide the bar when /bci/prediction has been quiet '
                                      'this long', unit='s', min=0.0)
    wait_for_eeg: bool = param(False, 'start the schedule once /eeg/raw flows (sessions turn '
                               'it on)')

    def __post_init__(self) -> None:
        check_classes(self.classes)
        if self.rest_min > self.rest_max:
            msg = (f"'rest_min' ({self.rest_min} s) is larger than 'rest_max' ({self.rest_max} "
                   's); swap them or make them equal for a fixed rest.')
            raise TrainerError(msg)


class GrazNode(rclpy.node.Node):
    """Publishes the Graz-BCI schedule of :class:`GrazProtocol` as it unfolds in ROS time."""

    node_traits = NodeTraits(name='graz_prompter', prompts=('graz',), parameters=GrazParams)

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.params = p = declare_params(self, GrazParams)
        # a TrainerError here (no class order keeps runs to max_repeat) ends the node with exit
        # code 2 and its one-line message (run_node)
        self.protocol = GrazProtocol(**{name: getattr(p, name) for name in _PROTOCOL})
        self.sequencer = PromptSequencer(self.protocol.schedule())
        self.n_trials = len(self.protocol.class_order())
        self.prediction: tuple[int, float] | None = None
        self.prediction_ns = 0  # ROS time of the latest prediction's arrival
        self.t0_ns: int | None = None
        self.done = rclpy.task.Future()  # result set when the session has ended
        # wait_for_eeg: the schedule starts once EEG flows (an amplifier that starts late on a
        # busy machine would otherwise miss the first trials)
        self.eeg_gate = EegGate(self) if p.wait_for_eeg else None

        self.prompt_pub = self.create_publisher(Prompt, TRAINER_PROMPT.name, TRAINER_PROMPT.qos)
        self.create_subscription(MIPrediction, BCI_PREDICTION.name, self.prediction_callback,
                                 BCI_PREDICTION.qos)
        self.create_timer(1.0 / p.rate, self.tick_callback)
        if p.display_rate > 0:
            self.display_pub = self.create_publisher(Image, TRAINER_DISPLAY.name,
                                                     TRAINER_DISPLAY.qos)
            self.create_timer(1.0 / p.display_rate, self.display_callback)
        self.get_logger().info(
            f'Graz-BCI session: {self.n_trials} trials, classes {list(self.protocol.classes)}, '
            f'seed {self.protocol.seed}, {self.protocol.total_duration():.1f} s planned.'
        )

    @property
    def finished(self) -> bool:
        return self.done.done()

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
        if self.params.duration > 0 and elapsed >= self.params.duration and not self.sequencer.done:
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
        p = self.params  # feedback and max_certainty are live: declare_params updates them in place
        age_ns = self.get_clock().now().nanoseconds - self.prediction_ns
        prediction = self.prediction if age_ns <= p.prediction_timeout * 1e9 else None
        frame = render_display(self.sequencer.current, prediction, p.display_width,
                               p.display_height, p.feedback, p.max_certainty)
        msg = cv2_to_imgmsg(frame, 'rgb8')
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
