"""Recorder QoS as rosbag2 does it, across real processes and a real bag.

A best-effort publisher (a camera) started after the recorder, while a reliable subscriber (the
vision node) already made its topic visible; the same publisher started before the recorder; a
best-effort publisher joining a reliable one on a topic already recorded (re-match); and a
declared topic that never gets a publisher (reported as not recorded, with the reason).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest
import yaml

from mindgrasp_bag import BagReader

pytestmark = pytest.mark.slow

#: Publishes std_msgs/String "<tag> <k>" on a topic with the given reliability until stopped,
#: 20 Hz; prints "publishing" once it runs.
PUBLISHER = '''
import sys, time
from mindgrasp_ros import rclpy
from mindgrasp_ros.interfaces.std_msgs.msg import String
q = rclpy.qos
topic, reliability, tag = sys.argv[1:4]
rclpy.init()
node = rclpy.node.Node('qos_test_publisher_' + tag)
qos = q.QoSProfile(depth=10, reliability=(q.ReliabilityPolicy.BEST_EFFORT
                   if reliability == 'best_effort' else q.ReliabilityPolicy.RELIABLE))
pub = node.create_publisher(String, topic, qos)
print('publishing', flush=True)
k = 0
try:
    while rclpy.ok():
        pub.publish(String(data=f'{tag} {k}'))
        k += 1
        rclpy.spin_once(node, timeout_sec=0.05)
except KeyboardInterrupt:
    pass
'''

#: A reliable subscriber only (as the vision node on the camera topics).
SUBSCRIBER = '''
import sys
from mindgrasp_ros import rclpy
from mindgrasp_ros.interfaces.std_msgs.msg import String
rclpy.init()
node = rclpy.node.Node('qos_test_subscriber')
node.create_subscription(String, sys.argv[1], lambda msg: None, 10)
print('subscribed', flush=True)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
'''


class _Proc:
    """A child process whose output lines are collected by a thread."""

    def __init__(self, args: list[str]) -> None:
        env = dict(os.environ, PYTHONUNBUFFERED='1')
        env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, env=env)
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip('\n'))

    def wait_for(self, text: str, timeout: float = 60.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if any(text in line for line in self.lines):
                return True
            if self.proc.poll() is not None:
                time.sleep(0.2)
                return any(text in line for line in self.lines)
            time.sleep(0.05)
        return False

    def stop(self) -> int:
        """SIGINT, then wait; returns the exit code once every output line is in ``lines``
        (the reader thread may still be reading the pipe when the process has ended)."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
        try:
            code = self.proc.wait(30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait(5)
        self._reader.join(30)
        return code


def _recorder(bag: Path, prefix: str, declared: str) -> _Proc:
    return _Proc([sys.executable, '-m', 'mindgrasp_bag.recorder_node', '--ros-args',
                  '-p', f'output:={bag}', '-p', f'regex:="^{prefix}/"',
                  '-p', f'topics:=["{declared}"]', '-p', 'discovery_period:=0.2'])


def _publisher(topic: str, reliability: str, tag: str) -> _Proc:
    return _Proc([sys.executable, '-c', PUBLISHER, topic, reliability, tag])


def _count(bag: Path, topic: str, tag: str) -> int:
    from mindgrasp_bag.typestore import typestore

    store = typestore()
    with BagReader(bag) as reader:
        texts = [store.deserialize_cdr(data, 'std_msgs/msg/String').data
                 for t, _, data in reader.messages([topic]) if t == topic]
    return sum(1 for text in texts if text.startswith(tag + ' '))


def _wait_recorded(recorder: _Proc, topic: str) -> None:
    assert recorder.wait_for(f'Subscribed to {topic}'), recorder.lines


@pytest.mark.parametrize('order', ['recorder_first', 'publisher_first'])
def test_best_effort_publisher_is_recorded_whatever_the_start_order(tmp_path, order):
    prefix = f'/qos_{uuid.uuid4().hex[:8]}'
    camera = f'{prefix}/camera_info'
    never = f'{prefix}/never_published'
    bag = tmp_path / 'bag'
    procs: list[_Proc] = []
    try:
        # A reliable subscriber makes the topic visible before any publisher exists: the old
        # recorder subscribed reliable then, and never matched the best-effort camera.
        procs.append(_Proc([sys.executable, '-c', SUBSCRIBER, camera]))
        assert procs[-1].wait_for('subscribed'), procs[-1].lines
        if order == 'publisher_first':
            procs.append(_publisher(camera, 'best_effort', 'cam'))
            assert procs[-1].wait_for('publishing'), procs[-1].lines
        recorder = _recorder(bag, prefix, never)
        assert recorder.wait_for('Recording to'), recorder.lines
        if order == 'recorder_first':
            procs.append(_publisher(camera, 'best_effort', 'cam'))
        _wait_recorded(recorder, camera)
        assert any('best_effort' in line for line in recorder.lines
                   if f'Subscribed to {camera}' in line), recorder.lines
        # wait for flushed chunks holding messages (the writer flushes every 1 s)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if any(p.proc.poll() is not None for p in procs):
                break
            if _count_if_readable(bag, camera, 'cam') >= 10:
                break
            time.sleep(0.5)
        assert recorder.stop() == 0, recorder.lines
    finally:
        for p in procs:
            p.stop()
    assert _count(bag, camera, 'cam') >= 10
    assert any(f'Not recorded: {never}: no node published or subscribed' in line
               for line in recorder.lines), recorder.lines
    meta = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert 'no node published or subscribed' in meta['custom_data'][f'not_recorded:{never}']
    assert f'not_recorded:{camera}' not in meta['custom_data']
    offered = meta['topics_with_message_count'][0]['topic_metadata']['offered_qos_profiles']
    assert [p['reliability'] for p in offered] == ['best_effort']


def test_a_best_effort_publisher_joining_a_reliable_one_is_matched_again(tmp_path):
    prefix = f'/qos_{uuid.uuid4().hex[:8]}'
    topic = f'{prefix}/camera_info'
    bag = tmp_path / 'bag'
    procs: list[_Proc] = []
    recorder = _recorder(bag, prefix, topic)
    try:
        assert recorder.wait_for('Recording to'), recorder.lines
        procs.append(_publisher(topic, 'reliable', 'driver'))
        _wait_recorded(recorder, topic)
        assert any('reliable' in line for line in recorder.lines
                   if f'Subscribed to {topic}' in line), recorder.lines
        procs.append(_publisher(topic, 'best_effort', 'sim'))
        assert recorder.wait_for(f'Subscribed again to {topic} with best_effort'), \
            recorder.lines
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and _count_if_readable(bag, topic, 'sim') < 10:
            time.sleep(0.5)
        assert recorder.stop() == 0, recorder.lines
    finally:
        for p in procs:
            p.stop()
        recorder.stop()
    assert _count(bag, topic, 'driver') >= 10
    assert _count(bag, topic, 'sim') >= 10
    assert any('0 dropped; 0 topic(s) not recorded' in line for line in recorder.lines), \
        recorder.lines


def _count_if_readable(bag: Path, topic: str, tag: str) -> int:
    try:
        return _count(bag, topic, tag)
    except Exception:  # the bag's first chunk may not be flushed yet
        return 0


def test_a_subscribed_only_topic_is_reported_not_recorded(tmp_path):
    prefix = f'/qos_{uuid.uuid4().hex[:8]}'
    topic = f'{prefix}/commands'
    bag = tmp_path / 'bag'
    listener = _Proc([sys.executable, '-c', SUBSCRIBER, topic])
    recorder = None
    try:
        assert listener.wait_for('subscribed'), listener.lines
        recorder = _recorder(bag, prefix, f'{prefix}/unused')
        assert recorder.wait_for('Recording to'), recorder.lines
        assert recorder.wait_for(f'Waiting for a publisher on {topic}'), recorder.lines
        assert recorder.stop() == 0, recorder.lines
    finally:
        listener.stop()
        if recorder is not None:
            recorder.stop()
    # a topic only listened to (as /trainer/prompt in every demo) is info, not a warning; a
    # topic the user named and never saw stays a warning
    assert any(f'Not recorded: {topic}: it had subscribers but no publisher' in line
               and '[INFO]' in line for line in recorder.lines), recorder.lines
    assert any(f'Not recorded: {prefix}/unused: no node published' in line and '[WARN]' in line
               for line in recorder.lines), recorder.lines
    assert not any('[WARN]' in line for line in recorder.lines if topic in line), recorder.lines
