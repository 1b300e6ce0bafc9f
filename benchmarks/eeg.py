"""EEG acquisition benchmark: push-to-publish latency across processes and the node's CPU use.

    ROS_DOMAIN_ID=12 .venv/bin/python benchmarks/eeg.py [--duration 30] [--chunk-period 0.03125]

Three processes: an LSL outlet pushing 32 channels at 250 Hz in blocks of 8 samples (every 32 ms,
like a g.Nautilus; each block is stamped with its push time, so the last sample's LSL timestamp
is the moment it was pushed), the acquisition node (``python -m mindgrasp_eeg.acquisition_node``,
default parameters), and this script as a subscriber of ``/eeg/raw``. Latency of a chunk = the
ROS time it arrived here minus the ROS stamp of its last sample (``header.stamp + (n-1)/rate``):
push -> LSL -> node -> DDS -> subscriber, an upper bound of push-to-publish. CPU = the node's
user+system CPU time over the measurement divided by the wall time (percent of one core).
Targets: p99 <= chunk period + 5 ms; CPU <= 5 % of one core.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
import uuid

import numpy as np


def source(name: str, duration: float) -> int:
    """The amplifier side: 8-sample blocks every 32 ms, stamped at push time."""
    import pylsl

    from mindgrasp_eeg.lsl import EEGOutlet
    from mindgrasp_eeg.montage import NAUTILUS_32
    from mindgrasp_eeg.synthetic import SyntheticEEG

    gen = SyntheticEEG(seed=0)
    outlet = EEGOutlet(name, NAUTILUS_32, 250.0)
    print('READY', flush=True)
    t0, k = time.monotonic(), 0
    while time.monotonic() - t0 < duration:
        due = int((time.monotonic() - t0) * 250.0)
        if due - k >= 8:
            outlet.push_volts(gen.generate(8), pylsl.local_clock())
            k += 8
        time.sleep(0.001)
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--duration', type=float, default=30.0, help='measurement (s)')
    parser.add_argument('--chunk-period', type=float, default=1 / 32, help='node parameter (s)')
    parser.add_argument('--source', metavar='NAME', help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.source:
        return source(args.source, args.duration + 30)

    import psutil
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk

    from mindgrasp_ros import rclpy

    env = dict(os.environ)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    name = f'mg_bench_eeg_{uuid.uuid4().hex[:8]}'
    src = subprocess.Popen([sys.executable, __file__, '--source', name, '--duration',
                            str(args.duration)], stdout=subprocess.PIPE,
                           stderr=subprocess.DEVNULL, text=True, env=env)
    assert src.stdout is not None and src.stdout.readline().strip() == 'READY'
    node = subprocess.Popen([sys.executable, '-m', 'mindgrasp_eeg.acquisition_node', '--ros-args',
                             '-p', f'stream_name:={name}', '-p',
                             f'chunk_period:={args.chunk_period}'],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    rclpy.init()
    sub = rclpy.node.Node('eeg_benchmark')
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(sub)
    arrivals: list[tuple[int, object]] = []
    qos = rclpy.qos.QoSProfile(depth=100, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT)
    sub.create_subscription(EEGChunk, '/eeg/raw',
                            lambda m: arrivals.append((sub.get_clock().now().nanoseconds, m)),
                            qos)
    try:
        deadline = time.monotonic() + 30
        while not arrivals and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.05)
        if not arrivals:
            print('no /eeg/raw message within 30 s: is the node running on this ROS_DOMAIN_ID?')
            return 1
        end = time.monotonic() + 2.0                  # warm-up (dejitter, discovery)
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
        arrivals.clear()
        proc = psutil.Process(node.pid)
        cpu0, wall0 = proc.cpu_times(), time.monotonic()
        end = wall0 + args.duration
        while time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
        cpu1, wall1 = proc.cpu_times(), time.monotonic()
    finally:
        node.terminate()
        src.terminate()
        node.wait(10)
        src.wait(10)
        sub.destroy_node()
        rclpy.try_shutdown()
    lat = []
    n_samples = 0
    for t_arr, m in arrivals:
        stamp = m.header.stamp.sec * 10**9 + m.header.stamp.nanosec
        last = stamp + (m.n_samples - 1) / m.sample_rate * 1e9
        lat.append((t_arr - last) * 1e-6)
        n_samples += m.n_samples
    lat_ms = np.array(lat)
    cpu = ((cpu1.user + cpu1.system) - (cpu0.user + cpu0.system)) / (wall1 - wall0) * 100
    period_ms = args.chunk_period * 1e3
    p50, p95, p99 = np.percentile(lat_ms, [50, 95, 99])
    print(f'EEG acquisition benchmark: 32 ch x 250 Hz, blocks of 8 samples, chunk period '
          f'{period_ms:.2f} ms, {wall1 - wall0:.1f} s, {len(lat_ms)} chunks, {n_samples} samples '
          f'({n_samples / (wall1 - wall0):.1f} samples/s)')
    print(f'push-to-publish latency (push -> subscriber): p50 {p50:.1f} ms, p95 {p95:.1f} ms, '
          f'p99 {p99:.1f} ms, max {lat_ms.max():.1f} ms (target p99 <= {period_ms + 5:.1f} ms: '
          f"{'met' if p99 <= period_ms + 5 else 'NOT met'})")
    print(f'acquisition node CPU: {cpu:.1f} % of one core (target <= 5 %: '
          f"{'met' if cpu <= 5 else 'NOT met'}); load average {os.getloadavg()[0]:.2f} on "
          f'{os.cpu_count()} cores')
    return 0


if __name__ == '__main__':
    sys.exit(main())
