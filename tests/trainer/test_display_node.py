"""The participant display node in its own process with real prompters, the simulator and vision
over DDS: flip stamps, headless frames (topic and PNG), a window under Xvfb, no-display error."""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from mindgrasp_trainer.display import ARROW_COLOUR, BAR_COLOUR

pytestmark = pytest.mark.slow


def pixels(img: np.ndarray, rgb: tuple[int, int, int], tol: int = 12) -> np.ndarray:
    return np.all(np.abs(img.astype(int) - rgb) <= tol, axis=2)


def read_png(path: Path) -> np.ndarray:
    return cv2.cvtColor(cv2.imread(str(path)), cv2.COLOR_BGR2RGB)


def green_robot(img: np.ndarray) -> np.ndarray:
    r, g, b = (img[:, :, i].astype(int) for i in range(3))
    return (g > r + 40) & (g > b + 40) & (g < 250)


@pytest.fixture
def xvfb(tmp_path):
    """A private X server (Xvfb) for the test; its DISPLAY string."""
    exe = shutil.which('Xvfb')
    if exe is None:
        pytest.skip('Xvfb is not installed (scripts/setup.sh installs it: apt-get install xvfb)')
    number = 50 + os.getpid() % 400
    proc = subprocess.Popen([exe, f':{number}', '-screen', '0', '1280x800x24', '-nolisten',
                             'tcp'], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    socket = Path(f'/tmp/.X11-unix/X{number}')
    deadline = time.monotonic() + 30
    while not socket.exists() and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    assert socket.exists(), 'Xvfb did not start'
    yield f':{number}'
    proc.terminate()
    proc.wait(10)


def test_graz_cues_are_drawn_stamped_and_saved(ros, make_node, spawn_node, spin_until, tmp_path):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import MIPrediction, Prompt

    from mindgrasp_trainer.ros_common import prompt_qos

    node = make_node('display_graz_observer')
    prompts, flips = [], []
    node.create_subscription(Prompt, '/trainer/prompt', prompts.append, prompt_qos())
    node.create_subscription(Prompt, '/display/flip', flips.append, 50)
    pred_pub = node.create_publisher(MIPrediction, '/bci/prediction', 10)
    png = tmp_path / 'png'
    display = spawn_node('mindgrasp_trainer.display_node', headless=True, png_dir=str(png),
                    rate=10.0, width=640, height=400, feedback='always', duration=120.0)
    assert spin_until(node, lambda: 'display ready' in display.output(), 60), display.output()
    graz = spawn_node('mindgrasp_trainer.graz_node', n_trials=2, classes='[1]', seed=0,
                 fixation=0.5, cue=1.0, imagery=1.0, rest_min=0.3, rest_max=0.3, start_delay=1.0,
                 display_rate=0.0)

    def publish_prediction() -> bool:
        pred_pub.publish(MIPrediction(class_index=1, certainty=0.8))
        return bool(prompts) and prompts[-1].phase == 'end' and len(flips) >= 9

    assert spin_until(node, publish_prediction, 90), (graz.output(), display.output())
    assert graz.wait(20) == 0
    # every prompt phase was drawn, after its prompt, and published with the flip time
    stamp = lambda m: m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec  # noqa: E731
    drawn = {(f.trial, f.phase): stamp(f) for f in flips}
    phases = [(p.trial, p.phase) for p in prompts]
    assert phases[0] == (1, 'fixation') and len(phases) == 9 and set(phases) <= set(drawn)
    for p in prompts:
        assert 0 <= drawn[(p.trial, p.phase)] - stamp(p) < 2.0
    # the PNG of a cue shows the arrow; of the imagery, the feedback bar to the right
    cue = read_png(sorted(png.glob('*_graz_001_cue.png'))[0])
    assert cue.shape == (400, 640, 3)
    _ys, xs = np.nonzero(pixels(cue, ARROW_COLOUR))
    assert len(xs) > 100 and xs.mean() > 320
    move = read_png(sorted(png.glob('*_graz_002_move.png'))[0])
    _ys, xs = np.nonzero(pixels(move, BAR_COLOUR))
    assert len(xs) > 100 and np.median(xs) > 320


def test_trainer_phase_in_a_window_under_xvfb_shows_both_robots(
    ros, make_node, spawn_node, spin_until, tmp_path, xvfb, monkeypatch,
):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    monkeypatch.setenv('DISPLAY', xvfb)
    node = make_node('display_trainer_observer')
    flips = []
    node.create_subscription(Prompt, '/display/flip', flips.append, 50)
    png = tmp_path / 'png'
    spawn_node('mindgrasp_sim.sim_node', trainer_robot=True, scene_camera_rate=5.0,
          scene_camera_width=320, scene_camera_height=240, camera_rate=2.0, duration=120.0)
    display = spawn_node('mindgrasp_trainer.display_node', png_dir=str(png), rate=5.0,
                    width=800, height=480, duration=120.0, phase_label='Trainer', n_trials=1)
    trainer = spawn_node('mindgrasp_trainer.trainer_node', n_trials=1, classes='[0]', seed=0,
                    turn_speed=0.8, move_duration=2.5, wait_duration=1.5, start_delay=3.0,
                    robot_timeout=60.0)
    assert spin_until(node, lambda: any(f.phase == 'end' for f in flips), 120), (
        trainer.output(), display.output())
    assert 'headless' not in display.output().split('display ready')[1].splitlines()[0]
    wait = read_png(sorted(png.glob('*_trainer_001_wait.png'))[0])
    assert wait.shape == (480, 800, 3)
    scene = wait[44:, : int(0.64 * 800)]
    # the training robot (green, blended over what is behind it) turned away from the user's
    # robot (dark grey links), both in the scene view
    assert np.count_nonzero(green_robot(scene)) > 300
    assert np.count_nonzero(np.all(scene < 60, axis=2)) > 300


def test_test_phase_shows_the_camera_with_the_green_box_and_the_target(
    ros, make_node, spawn_node, spin_until,
):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import TaskTarget
    from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

    node = make_node('display_test_observer')
    frames = []
    node.create_subscription(Image, '/display/image', frames.append,
                             ros.qos.qos_profile_sensor_data)
    latched = ros.qos.QoSProfile(depth=1, reliability=ros.qos.ReliabilityPolicy.RELIABLE,
                                 durability=ros.qos.DurabilityPolicy.TRANSIENT_LOCAL)
    target_pub = node.create_publisher(TaskTarget, '/task/target', latched)
    target_pub.publish(TaskTarget(trial=1, object_id=0, colour='red', shape='cube'))
    spawn_node('mindgrasp_sim.sim_node', camera_rate=5.0, duration=120.0)
    spawn_node('mindgrasp_vision.vision_node')
    spawn_node('mindgrasp_trainer.display_node', headless=True, rate=5.0, image_rate=2.0,
          width=800, height=480, layout='test', duration=120.0)

    def box_frame() -> bool:
        if not frames:
            return False
        m = frames[-1]
        img = np.asarray(m.data, np.uint8).reshape(m.height, m.width, 3)
        return np.count_nonzero(np.all(img[:, : int(0.6 * 800)] == (0, 255, 0), axis=2)) > 200

    assert spin_until(node, box_frame, 120)
    m = frames[-1]
    img = np.asarray(m.data, np.uint8).reshape(m.height, m.width, 3)
    assert np.count_nonzero(np.all(img == (220, 40, 40), axis=2)) >= 34 * 34   # red swatch


def test_no_display_gives_one_clear_line_and_exit_code_2(spawn_node, monkeypatch):
    monkeypatch.setenv('DISPLAY', '')
    monkeypatch.delenv('WAYLAND_DISPLAY', raising=False)
    proc = spawn_node('mindgrasp_trainer.display_node')
    assert proc.wait(60) == 2
    out = proc.output()
    assert 'No display is available' in out and '--headless' in out
    assert 'Traceback' not in out
