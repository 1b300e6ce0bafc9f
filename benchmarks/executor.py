"""Executor cost of a node with many readers: CPU of a subscriber process with one busy topic and
idle ones (as a node's parameter services and quiet topics are), over DDS between processes.

    .venv/bin/python benchmarks/executor.py                  # 100 msg/s, 12 idle topics, 20 s
    .venv/bin/python benchmarks/executor.py --rate 500 --idle 24 --seconds 30

A publisher process sends std_msgs/String at ``--rate``; the subscriber process subscribes to it
and to ``--idle`` topics nobody publishes. Prints the subscriber's CPU (user + system, % of one
core, psutil) and the messages it received. The executor waits on one DDS WaitSet and takes only
from the readers whose ReadCondition fired; a take from an empty reader costs ~5 us.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

ROLE_ENV = 'MINDGRASP_EXECUTOR_BENCH_ROLE'


def _publisher(rate: float) -> None:
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros import rclpy

    rclpy.init()
    node = rclpy.create_node('executor_bench_pub')
    pub = node.create_publisher(String, '/executor_bench/busy', 10)
    node.create_timer(1.0 / rate, lambda: pub.publish(String(data='x' * 100)))
    rclpy.spin(node)


def _subscriber(idle: int) -> None:
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros import rclpy

    rclpy.init()
    node = rclpy.create_node('executor_bench_sub')
    count = [0]

    def on_busy(_msg: String) -> None:
        count[0] += 1
        if count[0] % 100 == 0:
            print(count[0], flush=True)

    node.create_subscription(String, '/executor_bench/busy', on_busy, 10)
    for i in range(idle):
        node.create_subscription(String, f'/executor_bench/idle{i}', lambda _m: None, 10)
    rclpy.spin(node)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rate', type=float, default=100.0, help='messages per second (100)')
    parser.add_argument('--idle', type=int, default=12, help='idle subscriptions (12)')
    parser.add_argument('--seconds', type=float, default=20.0, help='measured time (20 s)')
    args = parser.parse_args()
    role = os.environ.get(ROLE_ENV)
    if role == 'pub':
        _publisher(args.rate)
        return 0
    if role == 'sub':
        _subscriber(args.idle)
        return 0
    import psutil

    procs = {}
    for name in ('sub', 'pub'):
        env = {**os.environ, ROLE_ENV: name}
        procs[name] = subprocess.Popen([sys.executable, __file__, *sys.argv[1:]], env=env,
                                       stdout=subprocess.PIPE if name == 'sub' else None,
                                       text=True)
    try:
        sub = procs['sub']
        assert sub.stdout is not None
        sub.stdout.readline()    # the first 100 messages arrived: discovery is done
        proc = psutil.Process(sub.pid)
        cpu0, wall0 = sum(proc.cpu_times()[:2]), time.monotonic()
        time.sleep(args.seconds)
        cpu1, wall1 = sum(proc.cpu_times()[:2]), time.monotonic()
    finally:
        for p in procs.values():
            p.kill()
            p.wait()
    share = 100.0 * (cpu1 - cpu0) / (wall1 - wall0)
    print(f'subscriber with 1 busy topic ({args.rate:g} msg/s) and {args.idle} idle ones: '
          f'{share:.1f} % of a core (load average {os.getloadavg()[0]:.1f})')
    print(json.dumps({'rate_hz': args.rate, 'idle_subscriptions': args.idle,
                      'subscriber_cpu_percent': round(share, 2)}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
