"""mindgrasp_ros: the ROS 2 client layer of MIndGrasp-ROS.

Node code imports rclpy from here::

    from mindgrasp_ros import rclpy
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

With ``MINDGRASP_RMW=rclpy`` (ROS 2 Jazzy installed and sourced) these resolve to the real rclpy
and its generated message classes. Otherwise they resolve to this package's runtime, which speaks
ROS 2 on the wire over Cyclone DDS like rmw_cyclonedds_cpp (see ``docs`` in the README).
"""

from __future__ import annotations

import os

__all__ = ['rclpy', 'typestore', 'using_real_rclpy']


def using_real_rclpy() -> bool:
    """True when ``MINDGRASP_RMW=rclpy`` selects the real rclpy."""
    return os.environ.get('MINDGRASP_RMW', '').strip().lower() == 'rclpy'


def __getattr__(name: str):
    if name == 'rclpy':
        import importlib

        if using_real_rclpy():  # pragma: no cover - needs a ROS 2 installation
            module = importlib.import_module('rclpy')
            for sub in ('clock', 'duration', 'executors', 'node', 'parameter', 'qos', 'time'):
                importlib.import_module(f'rclpy.{sub}')
        else:
            module = importlib.import_module('mindgrasp_ros.runtime')
        globals()['rclpy'] = module
        return module
    if name == 'typestore':
        from mindgrasp_ros.typesupport import typestore

        return typestore
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
