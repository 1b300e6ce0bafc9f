"""One graph per ROS domain: a node that must be alone (the simulator, the controller) looks for
a twin at its start and refuses to run beside one.

Two demos on one domain cross everything: two controllers command the same arm, two simulators
answer it, and neither run finishes a trial (issue 42). ROS 2 itself only warns about duplicate
node names (``ros2 node list``); a node calls :func:`refuse_second_graph` at the end of its
constructor, before it publishes anything, and raises its package's error (exit 2, one line
naming the domain to change) when, within a discovery period, the graph shows

- another node of its own fully qualified name (``/sim``, ``/fsm``):
  ``get_node_names_and_namespaces`` lists every node of every participant, duplicates included,
  as rcl does; or
- more publishers on one of its own output topics than it created itself (a second commander of
  ``/arm_controller/commands``): ``count_publishers``.

Only the graph API of rclpy is used, so it works with the real rclpy too. The discovery period
is the node's ``graph_check_wait`` parameter (s, default :data:`DEFAULT_WAIT`; 0 turns the check
off), counted from the node's creation: a simulator that spends that long loading its scene pays
nothing. Graphs hosted in one process on the in-process transport (lock-step) are not checked:
they have no domain to share.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping
from typing import Any

__all__ = ['DEFAULT_WAIT', 'declare_graph_check', 'domain_and_free', 'refuse_second_graph']

#: discovery period (s): on one host, Cyclone DDS discovers a running graph within a few hundred
#: milliseconds, also on a loaded machine
DEFAULT_WAIT = 1.5


def declare_graph_check(node: Any, default: float = DEFAULT_WAIT) -> float:
    """Declare the read-only ``graph_check_wait`` parameter (s) and return its value."""
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor

    desc = ParameterDescriptor(
        description='at start, look this long for a second graph on the ROS domain (another '
                    'node of this name, another publisher of its commands) and refuse to run '
                    'beside it; 0 turns the check off [s]',
        additional_constraints='read-only: restart the node to change it', read_only=True,
        floating_point_range=[FloatingPointRange(from_value=0.0, to_value=60.0)])
    return float(node.declare_parameter('graph_check_wait', float(default), desc).value)


def domain_and_free() -> tuple[str, int]:
    """This process's ROS domain (``ROS_DOMAIN_ID``, '0' when unset) and another one to suggest
    in the one-line refusals."""
    domain = os.environ.get('ROS_DOMAIN_ID', '') or '0'
    return domain, int(domain) + 1 if domain.isdigit() and int(domain) < 232 else 1


def _hosted_in_process(node: Any) -> bool:
    return getattr(getattr(node, 'context', None), 'transport', 'dds') == 'intra'


def refuse_second_graph(node: Any, error: type[Exception], *, started: float,
                        wait: float, own_publishers: Mapping[str, int] = {},
                        poll: float = 0.1) -> None:
    """Raise ``error`` (one line) when another graph runs on this node's domain.

    Parameters
    ----------
    node : rclpy.node.Node
        The node that must be alone; its own publishers exist already.
    error : type of Exception
        The package's error class (its ``run_node`` turns it into exit 2 and one line).
    started : float
        ``time.monotonic()`` at the node's creation (s): discovery ran since then.
    wait : float
        Discovery period (s) from ``started``; <= 0 skips the check.
    own_publishers : mapping of str to int
        Topic -> how many publishers this node has on it; more on the graph means another
        commander.
    poll : float
        Time between looks (s); a twin found early ends the wait at once.
    """
    if wait <= 0 or _hosted_in_process(node):
        return
    me = (node.get_name(), node.get_namespace())
    full = f"{me[1].rstrip('/')}/{me[0]}"
    deadline = started + wait
    while True:
        twins = sum(1 for entry in node.get_node_names_and_namespaces() if tuple(entry) == me)
        extra = {topic: node.count_publishers(topic) - own
                 for topic, own in own_publishers.items()}
        found = []
        if twins > 1:
            found.append(f'another node {full}')
        found += [f'{n} more publisher(s) on {topic}' for topic, n in extra.items() if n > 0]
        if found:
            domain, free = domain_and_free()
            msg = (f'Another ROS graph runs on ROS_DOMAIN_ID={domain} ({", ".join(found)}): two '
                   'graphs on one domain cross their commands, so this one does not start. '
                   f'Start it on another domain (e.g. ROS_DOMAIN_ID={free}) or stop the other '
                   'one first.')
            raise error(msg)
        if time.monotonic() >= deadline:
            return
        time.sleep(min(poll, max(0.0, deadline - time.monotonic())))
