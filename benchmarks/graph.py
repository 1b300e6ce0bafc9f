"""Graph queries: time per ``get_publishers_info_by_topic`` (what the recorder and the live view
ask about every topic they discover) with a graph of N topics, each with a publisher and a
subscription.

    .venv/bin/python benchmarks/graph.py [--topics 60] [--queries 500]

Prints the mean and p95 per query, and the first query (it reads every endpoint); the last line
is a JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import time
import uuid

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--topics', type=int, default=60)
    parser.add_argument('--queries', type=int, default=500)
    args = parser.parse_args()
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    node = rclpy.node.Node(f'graph_bench_{uuid.uuid4().hex[:6]}')
    prefix = f'/graph_bench_{uuid.uuid4().hex[:6]}'
    names = [f'{prefix}/t{i}' for i in range(args.topics)]
    keep = [node.create_publisher(String, n, 10) for n in names]
    keep += [node.create_subscription(String, n, lambda _m: None, 10) for n in names]
    t = time.perf_counter()
    node.get_publishers_info_by_topic(names[0])
    first_ms = (time.perf_counter() - t) * 1e3
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and sum(
            n in dict(node.get_topic_names_and_types()) for n in names) < len(names):
        time.sleep(0.05)
    times = []
    for i in range(args.queries):
        t = time.perf_counter()
        node.get_publishers_info_by_topic(names[i % len(names)])
        times.append((time.perf_counter() - t) * 1e3)
    result = {'topics': args.topics, 'endpoints': 2 * args.topics, 'first_query_ms': first_ms,
              'mean_ms': float(np.mean(times)), 'p95_ms': float(np.percentile(times, 95))}
    print(f"{args.topics} topics ({2 * args.topics} endpoints): first query "
          f"{first_ms:.1f} ms, then mean {result['mean_ms']:.2f} ms, p95 {result['p95_ms']:.2f} ms")
    print(json.dumps(result))
    node.destroy_node()
    rclpy.shutdown()


if __name__ == '__main__':
    main()
