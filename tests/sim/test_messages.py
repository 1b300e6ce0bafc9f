"""The simulator's ROS messages: encodings, units and frames, checked against the consumers'
own decoders (vision, virtual subject) where those packages are installed."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_sim import messages as msgs
from mindgrasp_sim.simulation import Simulation
from mindgrasp_sim.task import TaskEvent


@pytest.fixture(scope='module')
def sim():
    s = Simulation('set_locations')
    yield s
    s.close()


def test_stamp_and_header():
    t = msgs.stamp(12_345_678_901)
    assert (t.sec, t.nanosec) == (12, 345_678_901)
    h = msgs.header(t, 'world')
    assert h.frame_id == 'world' and h.stamp.sec == 12


def test_images_round_trip(sim):
    rgb, depth = sim.render_camera()
    color, depth_msg = msgs.image_messages(msgs.header(msgs.stamp(0), msgs.OPTICAL_FRAME),
                                           rgb, depth)
    assert (color.encoding, color.step, color.height, color.width) == ('rgb8', 384, 128, 128)
    assert (depth_msg.encoding, depth_msg.step, depth_msg.is_bigendian) == ('32FC1', 512, 0)
    np.testing.assert_array_equal(np.asarray(color.data).reshape(128, 128, 3), rgb)
    back = np.asarray(depth_msg.data, dtype=np.uint8).view('<f4').reshape(128, 128)
    np.testing.assert_array_equal(back, depth)
    from mindgrasp_vision import ros_conversions as conv

    np.testing.assert_array_equal(conv.rgb_from_image(color), rgb)
    np.testing.assert_array_equal(conv.depth_from_image(depth_msg), depth)


def test_camera_info(sim):
    k, w, h = sim.camera_intrinsics()
    info = msgs.camera_info(msgs.header(msgs.stamp(0), msgs.OPTICAL_FRAME), k, w, h)
    assert (info.width, info.height, info.distortion_model) == (128, 128, 'plumb_bob')
    np.testing.assert_allclose(np.asarray(info.k).reshape(3, 3), k)
    np.testing.assert_allclose(np.asarray(info.p).reshape(3, 4)[:, :3], k)
    assert np.all(np.asarray(info.d) == 0)


def test_pose_and_joint_state(sim):
    pos, quat = sim.ee_pose()
    pose = msgs.pose_stamped(msgs.header(msgs.stamp(0), 'world'), pos, quat)
    p, o = pose.pose.position, pose.pose.orientation
    np.testing.assert_allclose([p.x, p.y, p.z, o.x, o.y, o.z, o.w], [*pos, *quat])
    js = msgs.joint_state(msgs.header(msgs.stamp(0)), sim.joint_names, sim.joint_positions())
    assert list(js.name) == list(sim.joint_names)
    np.testing.assert_allclose(js.position, sim.home_pose, atol=1e-9)
    assert np.all(np.asarray(js.velocity) == 0) and len(js.effort) == 6


def test_object_markers(sim):
    markers = msgs.object_markers(msgs.header(msgs.stamp(0), 'world'), sim.objects()).markers
    assert [m.text for m in markers[:3]] == ['red cube', 'blue cylinder', 'yellow sphere']
    assert [m.type for m in markers[:3]] == [1, 3, 2]          # CUBE, CYLINDER, SPHERE
    assert markers[0].scale.x == pytest.approx(0.05) and markers[0].color.r > 0.8
    assert markers[1].pose.position.y == pytest.approx(0.5 * np.sin(np.radians(40)))
    from mindgrasp_common.markers import objects_from_markers

    seen = objects_from_markers(markers)       # what every subscriber of /sim/objects reads
    assert [(o.colour, o.shape) for o in seen[:3]] == [
        ('red', 'cube'), ('blue', 'cylinder'), ('yellow', 'sphere')]
    assert [o.object_id for o in seen] == [o.object_id for o in sim.objects()]
    np.testing.assert_allclose(seen[1].position, sim.objects()[1].position)


def test_grasp_result():
    event = TaskEvent(3, 'red cube', True, 12.5, 0.31, 'lifted above 0.22 m', 0)
    r = msgs.grasp_result(msgs.header(msgs.stamp(0), 'world'), event, 'red cube')
    assert (r.trial, r.grasped_object, r.desired_object, r.success) == (3, 'red cube',
                                                                         'red cube', True)
    assert r.duration == pytest.approx(12.5) and r.lift_height == pytest.approx(0.31)


def test_status():
    arr = msgs.status(msgs.header(msgs.stamp(0)), False, 'arm collision: palm - ground',
                      {'scene': 'set_locations', 'real_time_factor': '1.00'})
    (item,) = arr.status
    assert item.name == 'sim' and item.level == 1 and 'palm - ground' in item.message
    assert {kv.key: kv.value for kv in item.values}['scene'] == 'set_locations'
