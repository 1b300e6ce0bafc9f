"""Helpers for the bag tests (imported by tests/bag/test_bag_*.py, and by bringup tests that
write bags): sample messages, bags."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from mcap.reader import make_reader
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as RosbagsWriter

from mindgrasp_bag.typestore import typestore

EEG = 'mindgrasp_msgs/msg/EEGChunk'
IMAGE = 'sensor_msgs/msg/Image'
JOINTS = 'sensor_msgs/msg/JointState'
STRING = 'std_msgs/msg/String'


def _t(store, ns: int):
    sec, nanosec = divmod(ns, 1_000_000_000)
    return store.types['builtin_interfaces/msg/Time'](sec=sec, nanosec=nanosec)


def _header(store, ns: int, frame: str = ''):
    return store.types['std_msgs/msg/Header'](stamp=_t(store, ns), frame_id=frame)


def eeg_chunk(first_sample: int, n_samples: int = 25, n_channels: int = 32, seed: int = 0,
              stamp_ns: int = 0) -> bytes:
    """CDR of an EEGChunk (n_samples x n_channels float32, volts)."""
    store = typestore()
    rng = np.random.default_rng(seed + first_sample)
    msg = store.types[EEG](
        header=_header(store, stamp_ns, 'eeg'), sample_rate=250.0,
        channel_names=[f'C{i}' for i in range(n_channels)], n_samples=n_samples,
        first_sample_index=first_sample, unit='V',
        data=(rng.standard_normal(n_samples * n_channels) * 1e-5).astype(np.float32))
    return bytes(store.serialize_cdr(msg, EEG))


def image(i: int, width: int = 8, height: int = 6, encoding: str = 'rgb8') -> bytes:
    """CDR of a small Image whose pixels encode ``i``."""
    store = typestore()
    channels = {'rgb8': 3, '32FC1': 4}[encoding]
    data = np.full(width * height * channels, i % 256, dtype=np.uint8)
    msg = store.types[IMAGE](header=_header(store, i, 'camera'), height=height, width=width,
                             encoding=encoding, is_bigendian=0, step=width * channels, data=data)
    return bytes(store.serialize_cdr(msg, IMAGE))


def joints(i: int) -> bytes:
    """CDR of a JointState with six joints."""
    store = typestore()
    msg = store.types[JOINTS](header=_header(store, i), name=[f'j{k}' for k in range(6)],
                              position=np.arange(6, dtype=np.float64) * i,
                              velocity=np.zeros(6), effort=np.zeros(6))
    return bytes(store.serialize_cdr(msg, JOINTS))


def string(text: str) -> bytes:
    """CDR of a std_msgs/String."""
    store = typestore()
    return bytes(store.serialize_cdr(store.types[STRING](data=text), STRING))


def write_rosbags_bag(path: Path, messages: list[tuple[str, str, int, bytes]],
                      storage: StoragePlugin = StoragePlugin.MCAP,
                      extra_types: dict[str, tuple[str, str]] | None = None) -> Path:
    """Write ``(topic, type, t_ns, cdr)`` messages with rosbags' own Writer (not ours).

    ``extra_types`` maps a type name unknown to our store to ``(msgdef, rihs01)``.
    """
    store = typestore()
    connections = {}
    with RosbagsWriter(path, version=9, storage_plugin=storage) as writer:
        for topic, msgtype, _, _ in messages:
            if topic in connections:
                continue
            if extra_types and msgtype in extra_types:
                msgdef, digest = extra_types[msgtype]
                connections[topic] = writer.add_connection(topic, msgtype, msgdef=msgdef,
                                                           rihs01=digest)
            else:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
        for topic, _, stamp, data in messages:
            writer.write(connections[topic], stamp, data)
    return path


# ---------------------------------------------------------------- multi-process helpers
#: A publisher process: waits for the recorder to match, then publishes known CDR bytes on a
#: schedule (EEG chunks at 10 Hz, a latched String every 130 ms), prints "done" and exits.
PUBLISHER = '''
import sys, time
sys.path.insert(0, sys.argv[1])
from conftest_bag import eeg_chunk, string
from mindgrasp_ros import rclpy
QoSProfile, ReliabilityPolicy = rclpy.qos.QoSProfile, rclpy.qos.ReliabilityPolicy
DurabilityPolicy = rclpy.qos.DurabilityPolicy
prefix, n = sys.argv[2], int(sys.argv[3])
rclpy.init()
node = rclpy.node.Node('bag_test_publisher')
eeg = node.create_publisher('mindgrasp_msgs/msg/EEGChunk', prefix + '/eeg', 50, raw=True)
latched = QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
text = node.create_publisher('std_msgs/msg/String', prefix + '/chatter', latched, raw=True)
deadline = time.monotonic() + 20
while (eeg.get_subscription_count() == 0 or text.get_subscription_count() == 0) \\
        and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.05)
time.sleep(0.3)
t0 = time.monotonic()
events = sorted([(k * 0.100, 'eeg', k) for k in range(n)] +
                [(k * 0.130, 'text', k) for k in range(int(n * 100 / 130))])
for at, kind, k in events:
    while time.monotonic() - t0 < at:
        time.sleep(max(0.0, min(0.005, at - (time.monotonic() - t0))))
    if kind == 'eeg':
        eeg.publish(eeg_chunk(25 * k))
    else:
        text.publish(string(f'message {k}'))
time.sleep(0.5)
print('done', flush=True)
node.destroy_node()
rclpy.shutdown()
'''

#: A subscriber process: prints "<topic> <DDS source timestamp ns> <sha1 of the CDR bytes>" per
#: message; the source timestamp is taken by the publishing process when it writes the sample.
PROBE = '''
import hashlib, sys, time
from mindgrasp_ros import rclpy
QoSProfile, ReliabilityPolicy = rclpy.qos.QoSProfile, rclpy.qos.ReliabilityPolicy
rclpy.init()
node = rclpy.node.Node('bag_test_probe')
qos = QoSProfile(depth=200, reliability=ReliabilityPolicy.RELIABLE)
best_effort = QoSProfile(depth=200, reliability=ReliabilityPolicy.BEST_EFFORT)  # /clock
subs = []
for spec in sys.argv[1:]:
    topic, msgtype = spec.split('=')
    def cb(data, info, topic=topic):
        t = info.get('source_timestamp') or time.time_ns()
        print(topic, t, hashlib.sha1(bytes(data)).hexdigest(), flush=True)
    subs.append(node.create_subscription(msgtype, topic, cb,
                                         best_effort if topic == '/clock' else qos, raw=True))
print('ready', flush=True)
try:
    rclpy.spin(node)
except KeyboardInterrupt:
    pass
'''


def cut_in_half(path: Path) -> None:
    """What a copy interrupted half way leaves: the first half of the file."""
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])


def damage_chunks(path: Path, count: int = 3) -> list[int]:
    """Flip a bit inside ``count`` chunks spread over the file; their byte offsets."""
    with path.open('rb') as f:
        chunks = make_reader(f).get_summary().chunk_indexes
    picked = [chunks[round(i * (len(chunks) - 1) / (count + 1))] for i in range(1, count + 1)]
    data = bytearray(path.read_bytes())
    for chunk in picked:
        data[chunk.chunk_start_offset + chunk.chunk_length - 40] ^= 0x04
    path.write_bytes(bytes(data))
    return [c.chunk_start_offset for c in picked]


def cli_env() -> dict[str, str]:
    """Environment of a ``mindgrasp`` child process: unbuffered, discovery on this host."""
    env = dict(os.environ, PYTHONUNBUFFERED='1')
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return env


def mindgrasp_cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    """``mindgrasp ARGS`` in a child process, to its end (text stdout/stderr)."""
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, env=cli_env(), timeout=timeout)


def run_with_bag(tmp_path: Path, n: int = 30, chunk_size: int = 2000,
                 compression: str = 'none') -> Path:
    """A run directory with a finished bag of ``n`` EEG chunks and ``n`` strings at 10 Hz
    (bag time 1.0-3.9 s), in several MCAP chunks (``compression``: none, zstd or lz4)."""
    from mindgrasp_bag import BagWriter

    run = tmp_path / 'run'
    run.mkdir()
    with BagWriter(run / 'bag', chunk_size=chunk_size, compression=compression) as writer:
        writer.add_topic('/eeg/raw', EEG)
        writer.add_topic('/chatter', STRING)
        for k in range(n):
            writer.write('/eeg/raw', 1_000_000_000 + k * 100_000_000, eeg_chunk(25 * k))
            writer.write('/chatter', 1_000_000_000 + k * 100_000_000 + 1, string(f'm {k}'))
    return run
