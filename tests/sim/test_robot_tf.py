"""/robot_description, /tf and /tf_static follow the robot: for each shipped description the
simulator node (its own process, real DDS) publishes that robot's URDF, and its transforms make
one tree from the world frame through every URDF link to the camera's optical frame and the TCP,
with no frame its own parent (which tf2 refuses)."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pytest
from test_sim_node import spin_until, start

from mindgrasp_common.robot_description import load_robot, robot_names

pytestmark = pytest.mark.slow


@pytest.mark.parametrize('name', robot_names())
def test_description_and_tf_tree_are_the_robots(rclpy_ctx, spawn_node, name):
    from mindgrasp_ros.interfaces.std_msgs.msg import String
    from mindgrasp_ros.interfaces.tf2_msgs.msg import TFMessage

    from mindgrasp_ros.topics import ROBOT_DESCRIPTION, TF, TF_STATIC

    robot = load_robot(name)
    proc = start(spawn_node, f'robot:={name}')
    node = rclpy_ctx.node.Node(f'tf_probe_{name}')
    static, moving, urdf = [], [], []
    node.create_subscription(TFMessage, TF_STATIC.name, static.append, TF_STATIC.qos)
    node.create_subscription(TFMessage, TF.name, moving.append, TF.qos)
    node.create_subscription(String, ROBOT_DESCRIPTION.name, urdf.append,
                             ROBOT_DESCRIPTION.qos)
    assert spin_until(rclpy_ctx, node, lambda: static and moving and urdf, 60), proc.output()
    assert urdf[-1].data == robot.urdf.read_text(encoding='utf-8')
    links = {link.get('name') for link in ET.fromstring(urdf[-1].data).findall('link')}
    parent = {}
    for msg in (static[-1], moving[-1]):
        for t in msg.transforms:
            assert t.header.frame_id != t.child_frame_id, f'{t.child_frame_id} is its own parent'
            parent[t.child_frame_id] = t.header.frame_id
    # every frame reaches the world frame; the tree holds every link, the camera and the TCP
    for frame in parent:
        seen = {frame}
        while frame in parent:
            frame = parent[frame]
            assert frame not in seen, f'a loop through {frame}'
            seen.add(frame)
        assert frame == 'world'
    frames = set(parent) | {'world'}
    assert links <= frames, links - frames
    assert {'camera_color_optical_frame', 'tcp'} <= frames
    # the moving joints' links move on /tf: the arm joints' children among them
    assert {t.child_frame_id for t in moving[-1].transforms} & links
    node.destroy_node()
    proc.stop()
