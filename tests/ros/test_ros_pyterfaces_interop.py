"""Cross-check with an independent implementation: ros2-pyterfaces (RIHS01 hashes and CDR of
common_interfaces). Optional: ``pip install "ros2-pyterfaces[cyclone]"`` (alpha, not a project
dependency); the lead ran it for the issue note."""

import importlib

import numpy as np
import pytest

from mindgrasp_ros.typesupport import get_message_class, rihs01, serialize

pytest.importorskip('ros2_pyterfaces.cyclone.all_msgs',
                    reason='ros2-pyterfaces[cyclone] is not installed (optional cross-check)')

TYPES = ['sensor_msgs/msg/JointState', 'sensor_msgs/msg/Image', 'sensor_msgs/msg/CameraInfo',
         'std_msgs/msg/Float64MultiArray', 'geometry_msgs/msg/PoseStamped',
         'visualization_msgs/msg/MarkerArray', 'diagnostic_msgs/msg/DiagnosticArray',
         'rosgraph_msgs/msg/Clock', 'rcl_interfaces/msg/Log', 'std_msgs/msg/String']


@pytest.mark.parametrize('typename', TYPES)
def test_hash_and_cdr_match_ros2_pyterfaces(typename):
    pkg, _, name = typename.split('/')
    theirs = getattr(importlib.import_module(f'ros2_pyterfaces.cyclone.{pkg}.msg'), name)
    assert theirs.hash_rihs01() == rihs01(typename)
    if typename == 'sensor_msgs/msg/JointState':
        mine = get_message_class(typename)(name=['j1', 'j2'], position=np.array([1.0, 2.0]))
        other = theirs(name=['j1', 'j2'], position=[1.0, 2.0])
    else:
        mine, other = get_message_class(typename)(), theirs()
    assert bytes(other.serialize()).rstrip(b'\0') == serialize(mine).rstrip(b'\0')
