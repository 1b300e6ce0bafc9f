"""Transport benchmark of mindgrasp_ros: latency and sustained rate, cross- and in-process.

Run:  .venv/bin/python benchmarks/transport.py [--quick]

Cases: (a) EEGChunk 32 channels x 16 samples, (b) JointState with 6 joints, (c) 640x480 rgb8 Image.
Latency: the sender stamps each message with CLOCK_MONOTONIC (shared by all processes of a host);
the receiver subtracts on arrival, in its callback. Sustained rate: the highest tried rate at which
every message arrived (reliable QoS) and the sender kept the pace. Prints one table.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np

CASES = ('eeg', 'joint', 'image')
LATENCY_RATE_HZ = {'eeg': 250.0, 'joint': 250.0, 'image': 30.0}
RATE_STEPS_HZ = {'eeg': [500, 1000, 2000, 4000, 8000], 'joint': [500, 1000, 2000, 4000, 8000],
                 'image': [30, 60, 90, 120]}


def make_message(case: str):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk
    from mindgrasp_ros.interfaces.sensor_msgs.msg import Image, JointState

    if case == 'eeg':
        names = [f'ch{i}' for i in range(32)]
        return EEGChunk(sample_rate=250.0, channel_names=names, n_samples=16, unit='V',
                        data=np.random.default_rng(0).normal(size=32 * 16).astype(np.float32))
    if case == 'joint':
        return JointState(name=[f'joint_{i}' for i in range(1, 7)], position=np.zeros(6),
                          velocity=np.zeros(6), effort=np.zeros(6))
    return Image(height=480, width=640, encoding='rgb8', step=1920,
                 data=np.zeros(640 * 480 * 3, np.uint8))


def _qos(rclpy):
    return rclpy.qos.QoSProfile(depth=1000, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE)


def _stamp(msg) -> None:
    sec, nsec = divmod(time.monotonic_ns(), 1_000_000_000)
    msg.header.stamp.sec = sec
    msg.header.stamp.nanosec = nsec


def _latency_ns(msg) -> int:
    return time.monotonic_ns() - (msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)


def receiver(case: str, count: int, out: str, idle_s: float) -> None:
    """Subprocess: receive ``count`` messages (or stop after ``idle_s`` of silence)."""
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    node = rclpy.node.Node('bench_receiver')
    lat: list[int] = []
    cls = type(make_message(case))
    node.create_subscription(cls, f'/bench_{case}', lambda m: lat.append(_latency_ns(m)),
                             _qos(rclpy))
    print('ready', flush=True)
    last = time.monotonic()
    seen = 0
    while time.monotonic() - last < idle_s and len(lat) < count:
        rclpy.spin_once(node, timeout_sec=0.05)
        if len(lat) != seen:
            seen, last = len(lat), time.monotonic()
    with open(out, 'w') as f:
        json.dump(lat, f)
    node.destroy_node()
    rclpy.shutdown()


def _send(node, case: str, rate_hz: float, count: int) -> float:
    """Publish ``count`` messages at ``rate_hz``; returns the achieved rate."""
    from mindgrasp_ros import rclpy

    pub = node.create_publisher(type(make_message(case)), f'/bench_{case}', _qos(rclpy))
    deadline = time.monotonic() + 20
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    time.sleep(0.3)
    msg = make_message(case)
    period = 1.0 / rate_hz
    start = time.perf_counter()
    for i in range(count):
        target = start + i * period
        # sleep, never spin: a spinning sender holds the GIL and starves an in-process receiver
        while (now := time.perf_counter()) < target:
            time.sleep(target - now)
        _stamp(msg)
        pub.publish(msg)
    achieved = count / max(1e-9, time.perf_counter() - start)
    node.destroy_publisher(pub)
    return achieved


def cross_process(case: str, rate_hz: float, count: int) -> tuple[list[int], float]:
    from mindgrasp_ros import rclpy

    with tempfile.NamedTemporaryFile(suffix='.json', delete=False) as f:
        out = f.name
    proc = subprocess.Popen(
        [sys.executable, __file__, '--role', 'recv', '--case', case, '--count', str(count),
         '--out', out], stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    proc.stdout.readline()  # 'ready'
    node = rclpy.node.Node('bench_sender')
    achieved = _send(node, case, rate_hz, count)
    proc.wait(60)
    node.destroy_node()
    with open(out) as f:
        lat = json.load(f)
    os.unlink(out)
    return lat, achieved


def in_process(case: str, rate_hz: float, count: int) -> tuple[list[int], float]:
    from mindgrasp_ros import rclpy

    recv = rclpy.node.Node('bench_receiver_local')
    lat: list[int] = []
    recv.create_subscription(type(make_message(case)), f'/bench_{case}',
                             lambda m: lat.append(_latency_ns(m)), _qos(rclpy))
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(recv)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    thread = threading.Thread(target=spin, daemon=True)
    thread.start()
    send = rclpy.node.Node('bench_sender_local')
    achieved = _send(send, case, rate_hz, count)
    deadline = time.monotonic() + 5
    while len(lat) < count and time.monotonic() < deadline:
        time.sleep(0.01)
    stop.set()
    thread.join()
    executor.shutdown()
    recv.destroy_node()
    send.destroy_node()
    return lat, achieved


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--role', default='main', choices=['main', 'recv'])
    parser.add_argument('--case', choices=CASES)
    parser.add_argument('--count', type=int, default=0)
    parser.add_argument('--out')
    parser.add_argument('--quick', action='store_true', help='fewer messages (smoke run)')
    args = parser.parse_args()
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    if args.role == 'recv':
        receiver(args.case, args.count, args.out, idle_s=3.0)
        return
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    duration_s = 2.0 if args.quick else 6.0
    rows = []
    for mode, run in (('cross-process', cross_process), ('in-process', in_process)):
        for case in CASES:
            rate = LATENCY_RATE_HZ[case]
            lat, _ = run(case, rate, int(rate * duration_s))
            ms = np.asarray(lat, dtype=float) / 1e6
            sustained = 0.0
            for step in RATE_STEPS_HZ[case]:
                n = int(step * (1.0 if args.quick else 2.0))
                got, achieved = run(case, step, n)
                if len(got) == n and achieved >= 0.95 * step:
                    sustained = achieved
                else:
                    break
            rows.append((mode, case, rate, len(lat), int(rate * duration_s),
                         *np.percentile(ms, [50, 99]), ms.max(), sustained))
    rclpy.shutdown()
    print(f'{"mode":<14}{"case":<7}{"rate Hz":>8}{"recv/sent":>11}{"p50 ms":>8}{"p99 ms":>8}'
          f'{"max ms":>8}{"lossless Hz":>13}')
    for mode, case, rate, got, sent, p50, p99, mx, sustained in rows:
        label = f'>= {sustained:.0f}' if sustained else '< first step'
        print(f'{mode:<14}{case:<7}{rate:>8.0f}{f"{got}/{sent}":>11}{p50:>8.3f}{p99:>8.3f}'
              f'{mx:>8.3f}{label:>13}')
    print('lossless Hz: highest tried rate (steps: eeg/joint 500-8000, image 30-120) with every '
          'message delivered; ">=" because faster steps were not tried or lost messages.')


if __name__ == '__main__':
    main()
