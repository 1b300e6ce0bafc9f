"""``rclpy.utilities``."""

from mindgrasp_ros.runtime.arguments import remove_ros_args

__all__ = ['remove_ros_args']
