"""mindgrasp_msgs: the interface package of MIndGrasp-ROS.

The ``msg/`` and ``srv/`` folders hold the ROS 2 interface definitions; colcon builds them in a ROS
workspace (package.xml, CMakeLists.txt) and :mod:`mindgrasp_ros` registers the very same files at
run time. Import message classes through ``mindgrasp_ros.interfaces.mindgrasp_msgs.msg``.
"""

from pathlib import Path

#: Folder holding ``msg/`` and ``srv/``.
INTERFACE_DIR = Path(__file__).resolve().parent

__all__ = ['INTERFACE_DIR']
