"""Calls of a node's parameter services, shared by ``param list|get|set``."""

from __future__ import annotations

from typing import Any

from mindgrasp_cli.ros_cli import CliError


def call(node: Any, target: str, service: str, request: Any, timeout_s: float = 10.0,
         reply_timeout_s: float = 30.0) -> Any:
    """Call ``<target>/<service>`` (rcl_interfaces) and return the response: the service must
    be found within ``timeout_s`` (a wrong name fails fast), its reply may take up to
    ``reply_timeout_s`` (a node busy on a loaded machine still answers)."""
    from mindgrasp_ros import rclpy
    from mindgrasp_ros.typesupport import get_service_class

    srv = get_service_class('rcl_interfaces/srv/' + ''.join(
        p.capitalize() for p in service.split('_')))
    client = node.create_client(srv, f'{target.rstrip("/")}/{service}')
    if not client.wait_for_service(timeout_sec=timeout_s):
        msg = (f"Node {target!r} does not answer on {target}/{service} within {timeout_s:.0f} s;"
               ' check the name with `mindgrasp node list` and the ROS_DOMAIN_ID.')
        raise CliError(msg)
    future = client.call_async(request(srv))
    rclpy.spin_until_future_complete(node, future, timeout_sec=reply_timeout_s)
    if not future.done():
        raise CliError(f'{target}/{service} did not reply within {reply_timeout_s:.0f} s.')
    return future.result()
