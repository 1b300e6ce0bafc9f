"""Classifier node as a process over real DDS: /eeg/raw in, /bci/prediction, /bci/status out."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mindgrasp_classifier.training import TrainingConfig, train

from .classifier_synth import CHANNELS, RATE, make_recording

pytestmark = pytest.mark.slow


@pytest.fixture(scope='module')
def model_path(tmp_path_factory):
    model, _ = train([make_recording(trials_per_class=6, seed=0)], TrainingConfig(channels='all'),
                     cross_validate=False)
    return str(model.save(tmp_path_factory.mktemp('model') / 'synthetic'))


def level_of(status) -> int:
    lvl = status.level
    return int(lvl[0]) if isinstance(lvl, (bytes, bytearray)) else int(lvl)


class EegSource:
    """Test node: publishes EEGChunk on /eeg/raw, collects /bci/prediction and /bci/status."""

    def __init__(self, rclpy) -> None:
        from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, MIPrediction

        self.EEGChunk = EEGChunk
        self.node = rclpy.node.Node('classifier_test_source')
        self.executor = rclpy.executors.SingleThreadedExecutor()
        self.executor.add_node(self.node)
        sensor = rclpy.qos.QoSProfile(depth=100,
                                      reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT)
        self.pub = self.node.create_publisher(EEGChunk, '/eeg/raw', sensor)
        self.predictions: list = []
        self.status: list = []
        self.node.create_subscription(MIPrediction, '/bci/prediction',
                                      self.predictions.append, 10)
        self.node.create_subscription(DiagnosticArray, '/bci/status', self.status.append, 10)

    def spin(self, seconds: float, until=None) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.02)
            if until is not None and until():
                return True
        return until() if until is not None else True

    def publish(self, data: np.ndarray, first: int, rate: float = RATE, channels=CHANNELS,
                t0: float = 1000.0) -> None:
        msg = self.EEGChunk(sample_rate=rate, channel_names=list(channels),
                            n_samples=data.shape[0], first_sample_index=first, unit='V',
                            data=np.ascontiguousarray(data, dtype=np.float32).ravel())
        ns = round((t0 + first / rate) * 1e9)
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns // 10**9, ns % 10**9
        self.pub.publish(msg)

    def wait_matched(self, timeout: float = 60.0) -> bool:
        return self.spin(timeout, until=lambda: self.pub.get_subscription_count() > 0)

    def messages(self) -> list[str]:
        return [s.status[0].message for s in self.status]


@pytest.fixture
def source(rclpy_ctx):
    src = EegSource(rclpy_ctx)
    yield src
    src.node.destroy_node()


def test_node_predicts_with_window_stamps_and_reports_status(spawn_node, source, model_path):
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'duration:=300.0', '-p', 'status_period:=0.5')
    assert proc.wait_for_output('Loaded', 120), proc.output()
    assert source.wait_matched(60.0), 'the classifier did not subscribe to /eeg/raw'
    rec = make_recording(trials_per_class=2, seed=3)
    n_chunk = 4                                  # 1/32 s at 128 Hz
    n_send = round(3 * RATE)
    for k in range(0, n_send, n_chunk):
        source.publish(rec.data[k:k + n_chunk], k)
        source.spin(0.01)
    source.spin(60.0, until=lambda: len(source.predictions) >= 20)
    assert any('Filling the window' in m for m in source.messages()), source.messages()
    preds = source.predictions
    assert len(preds) >= 20, proc.output()
    # stamps: the last sample of each window, on the 1/16 s grid after the first full window
    idx = np.array([round(((p.header.stamp.sec + p.header.stamp.nanosec * 1e-9) - 1000.0) * RATE)
                    for p in preds])
    assert idx[0] == round(RATE) - 1 and np.all((idx + 1) % round(RATE / 16) == 0)
    p = preds[-1]
    d = np.asarray(p.distances)
    assert len(d) == 4 and list(p.class_names)[p.class_index] == \
        ['left_hand', 'right_hand', 'both_hands', 'both_feet'][int(np.argmin(d))]
    assert p.certainty == pytest.approx(d.mean() - d.min(), abs=1e-5)
    assert p.window_length == pytest.approx(1.0)
    # NaN in a channel: no prediction while it is in the window, and the status says why.
    # Predictions of the clean data may still be on their way: judge each by its window's stamp,
    # not by when it arrives.
    bad = rec.data[n_send:n_send + 2 * n_chunk].copy()
    bad[:, 5] = np.nan
    source.publish(bad, n_send)
    source.spin(0.05)
    for k in range(n_send + 2 * n_chunk, n_send + round(0.5 * RATE), n_chunk):
        source.publish(rec.data[k:k + n_chunk], k)
        source.spin(0.01)
    assert source.spin(60.0, until=lambda: any('Non-finite' in m and 'Cz' in m
                                               for m in source.messages())), source.messages()
    last = [round(((p.header.stamp.sec + p.header.stamp.nanosec * 1e-9) - 1000.0) * RATE)
            for p in source.predictions]
    assert max(last) < n_send, 'a prediction from a window holding NaN'
    assert any(level_of(s.status[0]) == 0 for s in source.status)


def test_node_refuses_a_stream_that_does_not_match(spawn_node, source, model_path):
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'duration:=300.0')
    assert proc.wait_for_output('Loaded', 120), proc.output()
    assert source.wait_matched()
    data = np.random.RandomState(0).randn(8, len(CHANNELS)) * 1e-5
    deadline = time.monotonic() + 60
    while proc.proc.poll() is None and time.monotonic() < deadline:
        source.publish(data, 0, rate=250.0)
        source.spin(0.2)
    assert proc.wait(10) == 1
    assert 'runs at 250.0 Hz but the model was trained at 128.0 Hz' in proc.output()
    assert any(level_of(s.status[0]) == 2 for s in source.status)


def test_node_refuses_missing_model_and_wrong_classes(spawn_node, tmp_path, model_path):
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={tmp_path / "nope.json"}')
    # a node refuses to start with a bad parameter: exit code 2 (mindgrasp_ros.node_main)
    assert proc.wait(180) == 2   # start-up alone takes a minute on a loaded machine
    assert 'does not exist; train one with' in proc.output()
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'classes:=[left_hand, right_hand]')
    assert proc.wait(180) == 2   # start-up alone takes a minute on a loaded machine
    assert "are expected; train the model on those classes" in proc.output()
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'adaptation:=wild')
    assert proc.wait(180) == 2   # start-up alone takes a minute on a loaded machine
    assert "The parameter 'adaptation' is 'wild'; use one of none, supervised" in proc.output()


def test_node_adapts_class_means_from_prompts(spawn_node, source, model_path, rclpy_ctx):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    latched = rclpy_ctx.qos.QoSProfile(
        depth=10, reliability=rclpy_ctx.qos.ReliabilityPolicy.RELIABLE,
        durability=rclpy_ctx.qos.DurabilityPolicy.TRANSIENT_LOCAL)
    prompts = source.node.create_publisher(Prompt, '/trainer/prompt', latched)
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'duration:=300.0', '-p', 'status_period:=0.5',
                      '-p', 'adaptation:=supervised', '-p', 'adaptation_rate:=0.01')
    assert proc.wait_for_output('Loaded', 120), proc.output()
    assert source.wait_matched()
    # the prompt (latched) must reach the classifier before the EEG it labels
    assert source.spin(60.0, until=lambda: prompts.get_subscription_count() > 0)
    cue = Prompt(paradigm='graz', class_index=0, class_name='left_hand', phase='cue', trial=1,
                 duration=4.0)
    cue.header.stamp.sec, cue.header.stamp.nanosec = 1000, 0       # stream time of sample 0
    prompts.publish(cue)
    source.spin(1.0)
    rec = make_recording(classes=(0,), trials_per_class=1, seed=3)
    for k in range(0, round(3 * RATE), 4):
        source.publish(rec.data[k:k + 4], k)
        source.spin(0.01)

    def updates() -> int:
        for s in reversed(source.status):
            values = {kv.key: kv.value for kv in s.status[0].values}
            if 'adaptive_updates' in values:
                return int(values['adaptive_updates'])
        return 0

    assert source.spin(60.0, until=lambda: updates() >= 10), (updates(), proc.output())
    assert proc.wait_for_output('adaptation supervised', 60), proc.output()


def test_node_stops_when_the_stream_layout_changes(spawn_node, source, model_path):
    proc = spawn_node('mindgrasp_classifier.classifier_node', '--ros-args', '-p',
                      f'model:={model_path}', '-p', 'duration:=300.0')
    assert proc.wait_for_output('Loaded', 120), proc.output()
    assert source.wait_matched()
    rec = make_recording(trials_per_class=1, seed=3)
    for k in range(0, 64, 4):
        source.publish(rec.data[k:k + 4], k)
        source.spin(0.01)
    extra = np.hstack([rec.data[64:68], rec.data[64:68, :1]])
    deadline = time.monotonic() + 60
    while proc.proc.poll() is None and time.monotonic() < deadline:
        source.publish(extra, 64, channels=[*CHANNELS, 'Oz'])
        source.spin(0.2)
    assert proc.wait(10) == 1
    assert 'changed from 12 channels at 128 Hz to 13 channels at 128 Hz' in proc.output()
