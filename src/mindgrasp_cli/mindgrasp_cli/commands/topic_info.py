"""Publishers and subscribers of a topic, with QoS and node names (like ``ros2 topic info``)."""

from __future__ import annotations

import argparse
import time

from mindgrasp_cli.ros_cli import CliError, cli_node, find_topic_type, print_error, topic_name


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('topic', type=topic_name, help='topic name')
    parser.add_argument('-v', '--verbose', action='store_true',
                        help='list every endpoint with node name, GID and QoS')


def _describe(info: object) -> str:
    q = info.qos_profile
    return (f'Node name: {info.node_name}\nNode namespace: {info.node_namespace}\n'
            f'Topic type: {info.topic_type}\nTopic type hash: {info.topic_type_hash}\n'
            f'Endpoint type: {info.endpoint_type}\n'
            f'GID: {".".join(f"{b:02x}" for b in info.endpoint_gid)}\nQoS profile:\n'
            f'  Reliability: {q.reliability.name}\n  History (Depth): '
            f'{q.history.name} ({q.depth})\n  Durability: {q.durability.name}\n'
            f'  Lifespan: {_dur(q.lifespan)}\n  Deadline: {_dur(q.deadline)}\n'
            f'  Liveliness: {q.liveliness.name}\n'
            f'  Liveliness lease duration: {_dur(q.liveliness_lease_duration)}\n')


def _dur(d: object) -> str:
    return 'Infinite' if d.nanoseconds == 0 else f'{d.nanoseconds} nanoseconds'


def main(args: argparse.Namespace) -> int:
    try:
        with cli_node('info') as node:
            typename = find_topic_type(node, args.topic)
            # endpoints are discovered before ros_discovery_info names their nodes: wait a
            # little for the names (a non-ROS DDS endpoint stays _NODE_NAME_UNKNOWN_)
            deadline = time.monotonic() + 3.0
            while True:
                pubs = node.get_publishers_info_by_topic(args.topic)
                subs = node.get_subscriptions_info_by_topic(args.topic)
                unknown = any(i.node_name == '_NODE_NAME_UNKNOWN_' for i in pubs + subs)
                if not unknown or time.monotonic() > deadline:
                    break
                time.sleep(0.1)
    except CliError as exc:
        return print_error(exc)
    # as ros2topic's info verb: one line each, a blank line after each only with --verbose
    end = '\n\n' if args.verbose else '\n'
    print(f'Type: {typename}', end=end)
    print(f'Publisher count: {len(pubs)}', end=end)
    if args.verbose:
        for info in pubs:
            print(_describe(info))
    print(f'Subscription count: {len(subs)}', end=end)
    if args.verbose:
        for info in subs:
            print(_describe(info))
    return 0
