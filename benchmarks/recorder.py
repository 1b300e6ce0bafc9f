"""Recorder throughput: sustained messages/s and MB/s without drops.

Run: ``ROS_DOMAIN_ID=16 .venv/bin/python benchmarks/recorder.py [--duration 10] [--only NAME]``

Scenarios (each prints published, recorded, dropped, msgs/s and MB/s):

* ``core-max``: the recorder core alone (queue + writer thread + MCAP file), fed as fast as one
  thread can push 1 MB messages, then 200-byte messages: the ceiling of the disk path.
* ``dds-eeg``: over real DDS between processes, EEG at 250 Hz x 32 channels in 10-sample
  chunks (25 msgs/s) plus 32-channel single-sample chunks at 250 msgs/s.
* ``dds-rgbd``: the session load: 640x480 rgb8 + 640x480 32FC1 depth + camera_info at 30 Hz,
  EEG chunks at 25 Hz, joint states at 100 Hz (~65 MB/s).
* ``dds-max``: 640x480 rgb8 images at increasing rates (60, 90, 120, 150, 200 Hz) until
  messages are lost: the highest rate recorded completely is the recorder's sustained maximum.
* ``dds-max-msgs``: the same for small messages (1 x 32 EEG chunks at 500 ... 4000 Hz).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
import uuid
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'tests'))

from conftest_bag import eeg_chunk, image  # noqa: E402
from mindgrasp_bag import BagReader, BagWriter, Recorder  # noqa: E402

PUBLISHER = r'''
import sys, time, json
sys.path.insert(0, sys.argv[1])
import numpy as np
from conftest_bag import eeg_chunk, joints
from mindgrasp_bag.typestore import typestore
from mindgrasp_ros import rclpy
prefix, scenario = sys.argv[2], sys.argv[3]
duration, max_rate = float(sys.argv[4]), float(sys.argv[5])
store = typestore()
def img(w, h, enc, step_bytes):
    T = store.types
    msg = T['sensor_msgs/msg/Image'](header=T['std_msgs/msg/Header'](), height=h, width=w,
        encoding=enc, is_bigendian=0, step=w * step_bytes,
        data=np.random.default_rng(0).integers(0, 255, w * h * step_bytes, dtype=np.uint8))
    return bytes(store.serialize_cdr(msg, 'sensor_msgs/msg/Image'))
def info():
    T = store.types
    return bytes(store.serialize_cdr(T['sensor_msgs/msg/CameraInfo'](
        header=T['std_msgs/msg/Header'](), height=480, width=640, distortion_model='plumb_bob',
        d=np.zeros(5), k=np.eye(3).ravel(), r=np.eye(3).ravel(), p=np.zeros(12),
        binning_x=0, binning_y=0, roi=T['sensor_msgs/msg/RegionOfInterest'](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)),
        'sensor_msgs/msg/CameraInfo'))
rclpy.init()
node = rclpy.node.Node('recorder_benchmark_publisher')
qos_sensor = rclpy.qos.QoSProfile(depth=5, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT)
streams = {
    'dds-eeg': [('/eeg/raw', 'mindgrasp_msgs/msg/EEGChunk', 25.0, [eeg_chunk(10 * k, 10)
                 for k in range(25)], 100),
                ('/eeg/single', 'mindgrasp_msgs/msg/EEGChunk', 250.0, [eeg_chunk(k, 1)
                 for k in range(25)], 100)],
    'dds-rgbd': [('/camera/color/image_raw', 'sensor_msgs/msg/Image', 30.0,
                  [img(640, 480, 'rgb8', 3)], qos_sensor),
                 ('/camera/depth/image_raw', 'sensor_msgs/msg/Image', 30.0,
                  [img(640, 480, '32FC1', 4)], qos_sensor),
                 ('/camera/color/camera_info', 'sensor_msgs/msg/CameraInfo', 30.0, [info()],
                  qos_sensor),
                 ('/eeg/raw', 'mindgrasp_msgs/msg/EEGChunk', 25.0,
                  [eeg_chunk(10 * k, 10) for k in range(25)], 100),
                 ('/joint_states', 'sensor_msgs/msg/JointState', 100.0, [joints(1)], 10)],
    'dds-max': [('/camera/color/image_raw', 'sensor_msgs/msg/Image', max_rate,
                 [img(640, 480, 'rgb8', 3)], 100)],
    'dds-max-msgs': [('/eeg/single', 'mindgrasp_msgs/msg/EEGChunk', max_rate,
                      [eeg_chunk(k, 1) for k in range(25)], 1000)],
}[scenario]
pubs = [(node.create_publisher(t, prefix + topic, q, raw=True), rate, data)
        for topic, t, rate, data, q in streams]
deadline = time.monotonic() + 20
while any(p.get_subscription_count() == 0 for p, _, _ in pubs) and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.05)
time.sleep(0.5)
counts = [0] * len(pubs)
nbytes = [0] * len(pubs)
t0 = time.monotonic()
next_t = [t0] * len(pubs)
while True:
    now = time.monotonic()
    if now - t0 >= duration:
        break
    for i, (pub, rate, data) in enumerate(pubs):
        if rate == 0.0 or now >= next_t[i]:
            d = data[counts[i] % len(data)]
            pub.publish(d)
            counts[i] += 1
            nbytes[i] += len(d)
            next_t[i] += 1.0 / rate if rate else 0.0
    if all(r > 0 for _, r, _ in pubs):
        time.sleep(max(0.0, min(next_t) - time.monotonic()))
elapsed = time.monotonic() - t0
time.sleep(1.0)
print(json.dumps({'topics': [prefix + s[0] for s in streams], 'counts': counts,
                  'bytes': nbytes, 'elapsed': elapsed}), flush=True)
node.destroy_node()
rclpy.shutdown()
'''


def _row(name: str, published: int, recorded: int, seconds: float, nbytes: int) -> None:
    dropped = published - recorded
    print(f'{name:<34} published {published:>7}  recorded {recorded:>7}  dropped {dropped:>5}  '
          f'{recorded / seconds:>9.1f} msgs/s  {nbytes / seconds / 1e6:>7.1f} MB/s')


def core_max(out: Path, duration: float) -> None:
    """Push as fast as possible into the recorder core; count what the writer thread takes."""
    for label, data, topic, msgtype in (
            ('core-max (921 kB rgb8 images)', image(1, 640, 480), '/img', 'sensor_msgs/msg/Image'),
            ('core-max (320 B EEG chunks, 1x32)', eeg_chunk(0, 1), '/eeg',
             'mindgrasp_msgs/msg/EEGChunk')):
        recorder = Recorder(BagWriter(out / f'core_{uuid.uuid4().hex[:6]}'),
                            max_queue_bytes=256 << 20)
        recorder.start()
        recorder.add_topic(topic, msgtype)
        pushed = 0
        t0 = time.monotonic()
        while time.monotonic() - t0 < duration:
            # Keep the queue short: this measures the sustained write rate, not queue memory.
            if recorder.queued_bytes < 32 << 20:
                recorder.push(topic, data)
                pushed += 1
            else:
                time.sleep(0.0005)
        counters = recorder.stop()
        elapsed = time.monotonic() - t0
        c = counters[topic]
        _row(label, pushed, c.written, elapsed, c.bytes_written)


def dds(scenario: str, out: Path, duration: float, rate: float = 0.0) -> tuple[int, float]:
    """Publisher process -> DDS -> recorder node process -> bag: (messages lost, recorded/s)."""
    env = dict(os.environ, PYTHONUNBUFFERED='1')
    env.setdefault('ROS_DOMAIN_ID', '16')
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    prefix = f'/bench_{uuid.uuid4().hex[:6]}'
    bag = out / f'{scenario}_{uuid.uuid4().hex[:6]}'
    recorder = subprocess.Popen(
        [sys.executable, '-m', 'mindgrasp_bag.recorder_node', '--ros-args',
         '-p', f'output:={bag}', '-p', f'regex:="^{prefix}/"', '-p', 'discovery_period:=0.2'],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        time.sleep(2.0)
        pub = subprocess.run([sys.executable, '-c', PUBLISHER, str(REPO / 'tests'),
                              prefix, scenario, str(duration), str(rate)],
                             env=env, capture_output=True, text=True, timeout=duration + 120)
    finally:
        recorder.send_signal(signal.SIGINT)
        log = recorder.communicate(timeout=120)[0]
    if pub.returncode != 0:
        print(f'{scenario}: the publisher failed:\n{pub.stderr[-2000:]}')
        return -1, 0.0
    import json

    result = json.loads(pub.stdout.strip().splitlines()[-1])
    with BagReader(bag) as reader:
        recorded = {name: info.message_count for name, info in reader.topics.items()}
    seconds = result['elapsed']
    for topic, count, nbytes in zip(result['topics'], result['counts'], result['bytes'],
                                    strict=True):
        got = recorded.get(topic, 0)
        _row(f'{scenario} {topic[len(prefix):]}', count, got, seconds,
             int(nbytes * got / max(count, 1)))
    total_pub, total_rec = sum(result['counts']), sum(recorded.values())
    total_bytes = sum(int(b * recorded.get(t, 0) / max(c, 1)) for t, c, b in zip(
        result['topics'], result['counts'], result['bytes'], strict=True))
    _row(f'{scenario} TOTAL' + (f' at {rate:.0f} Hz' if rate else ''), total_pub, total_rec,
         seconds, total_bytes)
    for line in log.splitlines():
        if 'because the write queue' in line or 'ERROR' in line or 'missing' in line:
            print('   recorder:', line.split('] ', 2)[-1])
    return total_pub - total_rec, total_rec / seconds


def main() -> int:
    """Run the scenarios and print one line per topic and a total per scenario."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--duration', type=float, default=10.0, help='seconds per scenario')
    parser.add_argument('--only', choices=('core-max', 'dds-eeg', 'dds-rgbd', 'dds-max',
                                           'dds-max-msgs'),
                        help='run one scenario')
    args = parser.parse_args()
    print(f'Recorder benchmark, {args.duration:.0f} s per scenario, {os.cpu_count()} CPU(s), '
          f'load average {os.getloadavg()[0]:.1f}')
    with tempfile.TemporaryDirectory(prefix='recorder_bench_') as tmp:
        out = Path(tmp)
        for name in ('core-max', 'dds-eeg', 'dds-rgbd', 'dds-max', 'dds-max-msgs'):
            if args.only not in (None, name):
                continue
            if name == 'core-max':
                core_max(out, args.duration)
            elif name in ('dds-max', 'dds-max-msgs'):
                best = 0.0
                rates = (60.0, 90.0, 120.0, 150.0, 200.0) if name == 'dds-max' else (
                    500.0, 1000.0, 2000.0, 4000.0)
                for rate in rates:
                    lost, achieved = dds(name, out, args.duration, rate)
                    if lost != 0:
                        break
                    best = achieved
                what = '640x480 rgb8 images' if name == 'dds-max' else '1x32 EEG chunks'
                print(f'{name}: highest rate of {what} recorded without loss: {best:.0f} msgs/s'
                      + (' (limited by the publisher)' if best and best < 0.97 * rate else ''))
            else:
                dds(name, out, args.duration)
    return 0


if __name__ == '__main__':
    sys.exit(main())
