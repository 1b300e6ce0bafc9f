"""Refuse a launch whose ROS domain already runs a graph with its simulator or controller.

Two demos on one domain cross every topic: two controllers command one arm, two simulators
answer, and neither finishes a trial, while both end "cleanly" (issue 42). Before the launcher
creates anything, :func:`check_domain_free` looks at the graph for a discovery period (through
``mindgrasp_ros``' rclpy API: ``get_node_names_and_namespaces``) and refuses in one line naming
the domain to change when one of the launch's own ``/sim`` or ``/fsm`` nodes is there already;
the running graph is not touched. The nodes check the same at their start
(:mod:`mindgrasp_ros.graph_check`), which covers ``ros2 launch``, ``mindgrasp run`` and two
launches started at the same moment.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from collections.abc import Iterable

from mindgrasp_launch.errors import LaunchError

__all__ = ['SINGLE_NODES', 'check_domain_free']

#: nodes a domain holds once: the arm's simulator and its controller
SINGLE_NODES = ('/sim', '/fsm')


def _graph_nodes(wait: float, wanted: set[str]) -> set[str]:
    """Fully qualified names of ``wanted`` seen on the domain within ``wait`` s."""
    from mindgrasp_ros import rclpy

    main = threading.current_thread() is threading.main_thread()
    handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)} \
        if main else {}
    context = rclpy.Context()
    rclpy.init(args=[], context=context)
    for sig, handler in handlers.items():   # the launcher's own, not rclpy's
        signal.signal(sig, handler)
    try:
        node = rclpy.node.Node(f'_mindgrasp_launch_{os.getpid()}', context=context,
                               start_parameter_services=False, enable_rosout=False)
        try:
            deadline = time.monotonic() + wait
            while True:
                seen = {f"{ns.rstrip('/')}/{name}"
                        for name, ns in node.get_node_names_and_namespaces()} & wanted
                if seen or time.monotonic() >= deadline:
                    return seen
                time.sleep(0.1)
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def check_domain_free(node_names: Iterable[str | None], wait: float) -> None:
    """Raise :class:`LaunchError` when one of ``node_names`` (of :data:`SINGLE_NODES`) already
    runs on this ROS domain; nothing when ``wait`` <= 0 or the launch has none of them.

    Parameters
    ----------
    node_names : iterable of str or None
        Fully qualified names of the launch's nodes.
    wait : float
        Discovery period (s).
    """
    wanted = {name for name in node_names if name in SINGLE_NODES}
    if wait <= 0 or not wanted:
        return
    seen = _graph_nodes(wait, wanted)
    if seen:
        from mindgrasp_ros.graph_check import domain_and_free

        domain, free = domain_and_free()
        msg = (f"another graph runs on ROS_DOMAIN_ID={domain} (its {', '.join(sorted(seen))} "
               'answered): a second one on the same domain would cross its commands, so nothing '
               f'was started. Launch on another domain (e.g. ROS_DOMAIN_ID={free} mindgrasp '
               'launch ...) or stop the other launch first.')
        raise LaunchError(msg)
