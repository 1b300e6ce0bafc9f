"""Participant display node: the screen a participant looks at during a session (pygame).

Run::

    python -m mindgrasp_trainer.display_node                         # a window
    python -m mindgrasp_trainer.display_node --fullscreen
    python -m mindgrasp_trainer.display_node --headless --ros-args -p png_dir:=frames

Shows (layout by phase, see :mod:`mindgrasp_trainer.screen`) the Graz cue and feedback bar, the
third-person scene with the green training robot, the eye-in-hand view with the vision overlay,
the desired object of a test, the controller state, and a banner with the phase and trial.

Topics (QoS):

==========================  ============================  ===============================
topic                       type                          QoS
==========================  ============================  ===============================
/trainer/prompt (sub)       mindgrasp_msgs/Prompt         reliable, transient local, 1
/bci/prediction (sub)       mindgrasp_msgs/MIPrediction   reliable, 10
/scene/image_raw (sub)      sensor_msgs/Image rgb8        sensor data
/vision/overlay (sub)       sensor_msgs/Image rgb8        sensor data
/fsm/state (sub)            mindgrasp_msgs/FsmState       reliable, transient local, 10
/task/target (sub)          mindgrasp_msgs/TaskTarget     reliable, transient local, 1
/trainer/ee_distance (sub)  std_msgs/Float64              reliable, 10
/display/flip (pub)         mindgrasp_msgs/Prompt         reliable, 50
/display/image (pub)        sensor_msgs/Image rgb8        sensor data (headless)
==========================  ============================  ===============================

Each new prompt phase is drawn at once (not at the next frame tick); right after the flip the node
publishes the prompt again on ``/display/flip`` with ``header.stamp`` = the time of the flip, so
labels can use display time, and logs a warning when the flip came more than ``late_threshold``
(20 ms) after the prompt's stamp. Frame times are checked every 5 s; a display that cannot keep
up with ``rate`` is logged with its measured frame times.

``--headless`` (or ``-p headless:=true``) draws off-screen (SDL dummy driver), publishes the frames
on ``/display/image`` at ``image_rate`` and writes PNG files to ``png_dir`` (one per prompt phase
and ``png_rate`` per second). Ends by itself after ``duration`` s when that is > 0, or when the
window is closed (Esc).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, MIPrediction, Prompt, TaskTarget
from mindgrasp_ros.interfaces.rcl_interfaces.msg import SetParametersResult
from mindgrasp_ros.interfaces.sensor_msgs.msg import Image
from mindgrasp_ros.interfaces.std_msgs.msg import Float64

from mindgrasp_ros import rclpy
from mindgrasp_ros import topics as tp
from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params, param
from mindgrasp_trainer.display import FEEDBACK_MODES
from mindgrasp_trainer.protocol import PromptEvent, TrainerError
from mindgrasp_trainer.screen import (
    LAYOUTS,
    ParticipantScreen,
    ScreenState,
    controller_instruction,
)
from mindgrasp_trainer.window import Window


@dataclass
class DisplayParams:
    """ROS parameters of the display node."""

    rate: float = param(30.0, 'frames per second', unit='Hz', min=0.5, max=240.0)
    width: int = param(1024, 'frame width', unit='px', min=320, max=7680)
    height: int = param(600, 'frame height', unit='px', min=240, max=4320)
    fullscreen: bool = param(False, 'take the whole screen (Esc ends)')
    headless: bool = param(False, 'draw off-screen; frames to /display/image and png_dir')
    layout: str = param('auto', 'screen layout; auto follows the prompts and targets',
                        choices=LAYOUTS[:-1])
    phase_label: str = param('', "banner text, e.g. 'Graz with feedback'; '' from the prompts")
    n_trials: int = param(0, 'trials planned in this phase, for the banner (0 unknown)', min=0)
    feedback: str = param('move', 'when the Graz feedback bar shows', choices=FEEDBACK_MODES,
                          live=True)
    max_certainty: float = param(1.0, 'certainty that fills the feedback bar', min=1e-6,
                                 live=True)
    prediction_timeout: float = param(1.0, 'older predictions are not shown', unit='s', min=0.0)
    late_threshold: float = param(0.02, 'a prompt drawn later than this after its stamp is '
                                  'logged', unit='s', min=0.0)
    image_rate: float = param(2.0, 'rate of /display/image when headless (0 off)', unit='Hz',
                              min=0.0, max=240.0)
    png_dir: str = param('', "folder for PNG frames ('' none)")
    png_rate: float = param(0.0, 'PNG frames per second besides one per prompt phase',
                            unit='Hz', min=0.0, max=240.0)
    duration: float = param(0.0, 'end after this long (0 = until stopped)', unit='s', min=0.0)


def _image_to_rgb(msg: Image) -> np.ndarray | None:
    """rgb uint8 (H, W, 3) of an rgb8 or bgr8 sensor_msgs/Image; None for other encodings."""
    if msg.encoding not in ('rgb8', 'bgr8') or msg.height == 0 or msg.width == 0:
        return None
    data = np.frombuffer(bytes(msg.data), np.uint8) if not isinstance(msg.data, np.ndarray) \
        else msg.data.astype(np.uint8, copy=False)
    rows = data.reshape(msg.height, msg.step)[:, :msg.width * 3]
    rgb = rows.reshape(msg.height, msg.width, 3)
    return rgb[:, :, ::-1].copy() if msg.encoding == 'bgr8' else rgb.copy()


def _stamp_ns(stamp) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


class DisplayNode(rclpy.node.Node):
    """Shows :class:`ParticipantScreen` frames and publishes when each prompt was drawn."""

    node_traits = NodeTraits(name='participant_display', participant_screen=True,
                             parameters=DisplayParams)

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.params = p = declare_params(self, DisplayParams)
        # a TrainerError here (no display, unwritable png_dir) ends the node with exit code 2
        # and its one-line message (run_node)
        self.screen = ParticipantScreen(int(p.width), int(p.height), p.layout, p.feedback,
                                        float(p.max_certainty))
        self.png_dir = Path(p.png_dir) if p.png_dir else None
        if self.png_dir is not None:
            try:
                self.png_dir.mkdir(parents=True, exist_ok=True)
            except OSError as err:
                msg = f"Cannot create 'png_dir' {p.png_dir!r}: {err}; give a writable folder."
                raise TrainerError(msg) from None
        self.window = Window(int(p.width), int(p.height), bool(p.fullscreen), bool(p.headless),
                             'MIndGrasp participant display')
        rate = float(p.rate)
        self.period = 1.0 / rate
        self.state = ScreenState(phase_label=str(p.phase_label), n_trials=int(p.n_trials))
        self.prediction: tuple[int, float] | None = None
        self.prediction_ns = 0
        self.pending: list[Prompt] = []       # prompts to stamp at the next flip
        self.frame_count = 0
        self.png_count = 0
        self.last_png = -math.inf
        self.last_image = -math.inf
        self.frame_ns: list[int] = []         # monotonic ns of the flips since the last check
        self.late_count = 0
        self.done = rclpy.task.Future()  # completed when the display ends (duration, Esc)

        self.flip_pub = self.create_publisher(Prompt, tp.DISPLAY_FLIP.name, tp.DISPLAY_FLIP.qos)
        self.image_pub = self.create_publisher(Image, tp.DISPLAY_IMAGE.name, tp.DISPLAY_IMAGE.qos)
        for topic, msg_type, callback in (
                (tp.TRAINER_PROMPT, Prompt, self.prompt_callback),
                (tp.BCI_PREDICTION, MIPrediction, self.prediction_callback),
                (tp.SCENE_IMAGE, Image, self.scene_callback),
                (tp.VISION_OVERLAY, Image, self.overlay_callback),
                (tp.FSM_STATE, FsmState, self.fsm_callback),
                (tp.TASK_TARGET, TaskTarget, self.target_callback),
                (tp.TRAINER_EE_DISTANCE, Float64, self.distance_callback)):
            self.create_subscription(msg_type, topic.name, callback, topic.qos)
        self.create_timer(self.period, self.frame_callback)
        self.create_timer(5.0, self.check_frame_times)
        end_after(self, float(p.duration))
        self.add_on_set_parameters_callback(self.live_parameters_callback)
        mode = 'headless' if p.headless else ('full screen' if p.fullscreen else 'window')
        self.get_logger().info(
            f'Participant display ready: {p.width}x{p.height} px at {rate:g} Hz, {mode}, '
            f"layout {p.layout}{', PNG frames to ' + str(self.png_dir) if self.png_dir else ''}.")

    @property
    def finished(self) -> bool:
        return self.done.done()

    # ------------------------------------------------------------------ inputs
    def live_parameters_callback(self, params: list) -> SetParametersResult:
        # declare_params validates the live parameters (feedback, max_certainty); the screen
        # takes the new values
        for param_ in params:
            if param_.name == 'feedback':
                self.screen.feedback = str(param_.value)
            elif param_.name == 'max_certainty':
                self.screen.max_certainty = float(param_.value)
        return SetParametersResult(successful=True)

    def prompt_callback(self, msg: Prompt) -> None:
        self.state.prompt = PromptEvent(_stamp_ns(msg.header.stamp) * 1e-9, msg.phase,
                                        int(msg.trial), int(msg.class_index),
                                        float(msg.duration), msg.paradigm)
        self.pending.append(msg)
        self.draw()  # a new cue is drawn now, not at the next frame tick

    def prediction_callback(self, msg: MIPrediction) -> None:
        self.prediction = (int(msg.class_index), float(msg.certainty))
        self.prediction_ns = self.get_clock().now().nanoseconds

    def scene_callback(self, msg: Image) -> None:
        self.state.scene = _image_to_rgb(msg)

    def overlay_callback(self, msg: Image) -> None:
        self.state.camera = _image_to_rgb(msg)

    def fsm_callback(self, msg: FsmState) -> None:
        self.state.fsm_state_name = str(msg.state_name) or str(int(msg.state))
        self.state.instruction = controller_instruction(msg.paradigm, int(msg.state),
                                                        bool(msg.offered),
                                                        list(msg.yes_classes),
                                                        list(msg.no_classes))
        self.state.evidence = float(max(msg.confirm_evidence, msg.cancel_evidence))

    def target_callback(self, msg: TaskTarget) -> None:
        self.state.target = f'{msg.colour} {msg.shape}'.strip()
        self.state.target_trial = int(msg.trial)

    def distance_callback(self, msg: Float64) -> None:
        self.state.ee_distance = float(msg.data)

    # ------------------------------------------------------------------ frames
    def frame_callback(self) -> None:
        if self.finished:
            return
        if not self.window.poll():
            self.get_logger().info('The display window was closed; the display ends.')
            self.done.set_result(0)
            return
        self.draw()

    def draw(self) -> None:
        """Render, flip, then stamp the pending prompts with the flip time."""
        age_ns = self.get_clock().now().nanoseconds - self.prediction_ns
        timeout_ns = int(float(self.params.prediction_timeout) * 1e9)
        self.state.prediction = self.prediction if age_ns <= timeout_ns else None
        frame = self.screen.render(self.state)
        flip_mono = self.window.show(frame)
        flip = self.get_clock().now()
        self.frame_ns.append(flip_mono)
        self.frame_count += 1
        prompts, self.pending = self.pending, []
        for prompt in prompts:
            late = (flip.nanoseconds - _stamp_ns(prompt.header.stamp)) * 1e-9
            prompt.header.stamp = flip.to_msg()
            self.flip_pub.publish(prompt)
            if late > float(self.params.late_threshold):
                self.late_count += 1
                self.get_logger().warning(
                    f'Trial {prompt.trial}: {prompt.phase} {prompt.class_name or ""} drawn '
                    f'{1e3 * late:.1f} ms after its prompt (limit '
                    f'{1e3 * float(self.params.late_threshold):.0f} ms); /display/flip has the '
                    'drawn time.')
        # the PNG and image rates count on the node clock (simulated time in lock-step)
        now = flip.nanoseconds * 1e-9
        image_rate = float(self.params.image_rate)
        if self.params.headless and image_rate > 0 and now - self.last_image >= 1 / image_rate:
            self.last_image = now
            msg = cv2_to_imgmsg(frame, 'rgb8')
            msg.header.stamp = flip.to_msg()
            msg.header.frame_id = 'participant_display'
            self.image_pub.publish(msg)
        if self.png_dir is not None and (
                prompts or (self.params.png_rate > 0
                            and now - self.last_png >= 1 / self.params.png_rate)):
            self.last_png = now
            self.write_png(frame, prompts[-1] if prompts else None)

    def write_png(self, frame: np.ndarray, prompt: Prompt | None) -> None:
        """``<png_dir>/frame_<n>[_<paradigm>_<trial>_<phase>].png``; a full disk is logged once."""
        self.png_count += 1
        tag = f'_{prompt.paradigm}_{prompt.trial:03d}_{prompt.phase}' if prompt else ''
        path = self.png_dir / f'frame_{self.png_count:06d}{tag}.png'
        if not cv2.imwrite(str(path), cv2.cvtColor(frame, cv2.COLOR_RGB2BGR)):
            self.get_logger().error(f'Could not write {path}; PNG frames stop.')
            self.png_dir = None

    def check_frame_times(self) -> None:
        """Warn, with the measured frame times, when frames come slower than ``rate``.

        Frame times are wall time (the screen's); on simulated time (lock-step) frames follow
        the simulated clock, so their wall-time gaps say nothing about the screen: no check."""
        ns, self.frame_ns = self.frame_ns, self.frame_ns[-1:]
        if len(ns) < 3 or self.get_parameter('use_sim_time').value:
            return
        dt = np.diff(np.asarray(ns)) * 1e-6  # ms
        p95 = float(np.percentile(dt, 95))
        if p95 > 1.5 * self.period * 1e3:
            self.get_logger().warning(
                f'The display cannot keep up: frame times median {np.median(dt):.1f} ms, '
                f'95th percentile {p95:.1f} ms, max {dt.max():.1f} ms over {len(dt)} frames, '
                f'for {1e3 * self.period:.1f} ms at rate {1 / self.period:g} Hz; lower '
                "'rate' or the frame size.")

    def destroy_node(self) -> None:
        self.get_logger().info(
            f'Participant display drew {self.frame_count} frames, {self.late_count} late '
            f'prompt(s), {self.png_count} PNG file(s).')
        self.window.close()
        super().destroy_node()


def _cli_flags(args: list[str]) -> list[str]:
    """``--headless`` / ``--fullscreen`` before ``--ros-args`` become ROS parameters."""
    args = list(args)
    extra = []
    own = args[:args.index('--ros-args')] if '--ros-args' in args else args
    for flag in ('--headless', '--fullscreen'):
        if flag in own:
            args.remove(flag)
            extra += ['-p', f'{flag[2:]}:=true']
    if extra:
        if '--ros-args' in args:
            i = args.index('--ros-args') + 1
            args[i:i] = extra
        else:
            args += ['--ros-args', *extra]
    return args


def main(args: list[str] | None = None) -> int:
    argv = _cli_flags(sys.argv[1:] if args is None else args)
    return run_node(DisplayNode, [sys.argv[0], *argv], errors=(TrainerError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
