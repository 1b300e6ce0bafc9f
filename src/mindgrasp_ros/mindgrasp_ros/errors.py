"""Exceptions of the ROS 2 client layer."""


class RosError(Exception):
    """Base class of every error raised by :mod:`mindgrasp_ros`."""
