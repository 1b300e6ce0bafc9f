"""Graz prompter node across processes: prompts over DDS with the schedule's timing, transient-local
late joiner, display frames, bad parameters."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mindgrasp_trainer.display import ARROW_COLOUR, DIRECTIONS
from mindgrasp_trainer.graz import GrazProtocol

pytestmark = pytest.mark.slow

FAST = {'fixation': 0.4, 'cue': 0.3, 'imagery': 0.5, 'rest_min': 0.2, 'rest_max': 0.4}


def prompt_qos(rclpy, depth: int = 10):
    """Reliable, transient local; a collecting reader keeps 10 so a stalled test loses nothing."""
    return rclpy.qos.QoSProfile(
        depth=depth,
        reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
        durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL,
    )


def stamp_s(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_prompts_arrive_in_order_with_the_schedule_timing(ros, make_node, spawn_node, spin_until):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    node = make_node('graz_listener')
    got = []  # (message, receive time in ROS seconds)
    node.create_subscription(
        Prompt, '/trainer/prompt',
        lambda m: got.append((m, node.get_clock().now().nanoseconds * 1e-9)), prompt_qos(ros),
    )  # fmt: skip
    # Start delay covers process start-up and discovery, so the listener sees the whole session.
    proc = spawn_node('mindgrasp_trainer.graz_node', n_trials=4, seed=3, start_delay=2.0,
                 display_rate=0.0, **FAST)  # fmt: skip
    expected = GrazProtocol(n_trials=4, seed=3, start_delay=2.0, **FAST).schedule()
    assert spin_until(node, lambda: got and got[-1][0].phase == 'end', 120.0), (
        f'prompts received: {[m.phase for m, _ in got]}; node output:\n{proc.output()}'
    )
    assert proc.wait(60) == 0
    msgs = [m for m, _ in got]
    assert [(m.phase, m.class_index, m.trial) for m in msgs] == [
        (e.phase, e.class_index, e.trial) for e in expected
    ]
    assert [m.class_name for m in msgs] == [e.class_name for e in expected]
    assert [m.paradigm for m in msgs] == ['graz'] * len(expected)
    durations = [e.duration for e in expected]
    np.testing.assert_allclose([m.duration for m in msgs], durations, atol=1e-6)
    # phase onsets (header stamps) follow the planned onsets, late only by the
    # timer's scheduling delay, which does not add up over the session (onsets are planned from
    # the start, not from the previous phase). Exact timing on sim time: test_trainer_lockstep.
    stamps = np.array([stamp_s(m) for m in msgs])
    onsets = np.array([e.onset for e in expected])
    lag = stamps - onsets
    lag -= lag.min()  # relative to the least-delayed phase (the protocol start is not published)
    # (bounds generous for a loaded machine: a drift that adds up would exceed them)
    assert np.median(lag) < 0.25 and lag.max() < 1.0, lag
    # each prompt reached the other process after it was stamped
    delays = np.array([t for _, t in got]) - stamps
    assert (delays > -0.01).all(), delays


def test_late_joiner_gets_the_last_prompt_and_the_display_shows_the_arrow(
    ros, make_node, spawn_node, spin_until,
):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt
    from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

    node = make_node('graz_late_joiner')
    early, late, frames = [], [], []
    node.create_subscription(Prompt, '/trainer/prompt', early.append, prompt_qos(ros))
    node.create_subscription(Image, '/trainer/display', frames.append,
                             ros.qos.qos_profile_sensor_data)  # fmt: skip
    proc = spawn_node('mindgrasp_trainer.graz_node', n_trials=4, seed=5, start_delay=2.0,
                 fixation=0.5, cue=60.0, display_rate=20.0, display_width=160,
                 display_height=120)  # fmt: skip
    assert spin_until(node, lambda: any(m.phase == 'cue' for m in early), 120.0), (
        f'no cue; node output:\n{proc.output()}'
    )
    cue = early[-1]
    assert [m.phase for m in early] == ['fixation', 'cue']
    # a reader that joins now (during the 60 s cue) gets only the current phase (the writer keeps
    # depth 1), even when it would keep 10
    node.create_subscription(Prompt, '/trainer/prompt', late.append, prompt_qos(ros, 10))
    assert spin_until(node, lambda: late, 60.0)
    spin_until(node, lambda: False, 0.5)
    assert len(late) == 1
    assert (late[0].phase, late[0].trial, late[0].class_index) == ('cue', 1, cue.class_index)
    assert late[0].header.stamp.sec == cue.header.stamp.sec
    assert late[0].header.stamp.nanosec == cue.header.stamp.nanosec
    # the display shows the arrow of the cued class, pointing its way
    n = len(frames)
    assert spin_until(node, lambda: len(frames) > n + 2, 60.0)
    img = frames[-1]
    assert (img.width, img.height, img.encoding) == (160, 120, 'rgb8')
    rgb = np.asarray(img.data, np.uint8).reshape(120, 160, 3)
    ys, xs = np.nonzero(np.all(rgb == ARROW_COLOUR, axis=-1))
    assert len(xs) > 50
    dx, dy = DIRECTIONS[cue.class_index]
    centre = np.array([xs.mean() - 80, ys.mean() - 60])
    assert np.dot(centre, [dx, dy]) > 5


def test_duration_ends_the_session(ros, make_node, spawn_node, spin_until):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    node = make_node('graz_duration_listener')
    got = []
    node.create_subscription(Prompt, '/trainer/prompt', got.append, prompt_qos(ros))
    t0 = time.monotonic()
    proc = spawn_node('mindgrasp_trainer.graz_node', n_trials=400, duration=2.5, start_delay=0.5,
                 display_rate=0.0, **FAST)  # fmt: skip
    assert proc.wait(300) == 0
    assert time.monotonic() - t0 < 300     # 400 trials would take 640 s
    assert spin_until(node, lambda: got and got[-1].phase == 'end', 60.0)


@pytest.mark.parametrize(
    ('params', 'match'),
    [
        ({'rest_min': 3.0, 'rest_max': 2.0}, "'rest_min' (3.0 s) is larger than 'rest_max'"),
        ({'classes': '[0, 7]'}, 'which are not class indices'),
        ({'feedback': 'loud'}, "'feedback' is 'loud'; use one of off, move, always"),
    ],
)
def test_bad_parameters_end_the_node_with_the_reason(ros, spawn_node, params, match):
    proc = spawn_node('mindgrasp_trainer.graz_node', **params)
    assert proc.wait(120) == 2
    out = proc.output()
    assert match in out, out


def test_live_display_parameters_and_fixed_protocol_parameters(
    ros, make_node, spawn_node, spin_until,
):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import MIPrediction, Prompt
    from mindgrasp_ros.interfaces.rcl_interfaces.srv import SetParameters
    from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

    from mindgrasp_trainer.display import BAR_COLOUR

    node = make_node('graz_param_client')
    frames = []
    node.create_subscription(Image, '/trainer/display', frames.append,
                             ros.qos.qos_profile_sensor_data)  # fmt: skip
    pred_pub = node.create_publisher(MIPrediction, '/bci/prediction', 10)
    client = node.create_client(SetParameters, '/graz_prompter/set_parameters')
    # a long fixation: the feedback bar shows only when 'feedback' is 'always'
    spawn_node('mindgrasp_trainer.graz_node', start_delay=0.5, fixation=60.0, display_rate=20.0,
          display_width=160, display_height=120, duration=300.0)  # fmt: skip
    assert client.wait_for_service(timeout_sec=120.0)
    prompts = []
    node.create_subscription(Prompt, '/trainer/prompt', prompts.append, prompt_qos(ros))
    assert spin_until(node, lambda: prompts and prompts[-1].phase == 'fixation', 120.0)

    def set_param(name, value):
        req = SetParameters.Request(
            parameters=[ros.parameter.Parameter(name, value=value).to_parameter_msg()]
        )
        future = client.call_async(req)
        assert spin_until(node, future.done, 60.0)
        return future.result().results[0]

    def bar_pixels() -> int:
        """Green pixels of the newest frame."""
        rgb = np.asarray(frames[-1].data, np.uint8).reshape(120, 160, 3)
        return int(np.all(rgb == BAR_COLOUR, axis=-1).sum())

    def predicting(until, timeout: float = 60.0) -> bool:
        """Publish predictions (right hand, 0.9) at 20 Hz until a new frame meets ``until()``."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            pred_pub.publish(MIPrediction(class_index=1, certainty=0.9))
            n = len(frames)
            if spin_until(node, lambda n=n: len(frames) > n, 0.05) and until():
                return True
        return False

    assert pred_pub.get_subscription_count() > 0 or spin_until(
        node, lambda: pred_pub.get_subscription_count() > 0, 60.0)
    assert set_param('feedback', 'always').successful
    assert predicting(lambda: bar_pixels() > 100)  # the predictions arrive and are drawn
    # a classifier that goes quiet: the bar disappears after prediction_timeout (1 s)
    assert spin_until(node, lambda: bar_pixels() == 0, 60.0)
    assert set_param('feedback', 'move').successful
    # 'move': no feedback during the fixation, however many predictions arrive (40 frames)
    n = len(frames)
    predicting(lambda: len(frames) > n + 40)
    assert bar_pixels() == 0
    bad = set_param('feedback', 'loud')
    assert not bad.successful and "'feedback' is 'loud'" in bad.reason
    fixed = set_param('n_trials', 8)
    assert not fixed.successful
    assert "'n_trials' is read-only" in fixed.reason, fixed.reason
