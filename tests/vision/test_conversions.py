"""sensor_msgs/Image <-> numpy and Detection -> mindgrasp_msgs, with the encodings cameras use."""

from __future__ import annotations

import math

import numpy as np
import pytest
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Detection as DetectionMsg
from mindgrasp_ros.interfaces.sensor_msgs.msg import Image, RegionOfInterest
from mindgrasp_ros.interfaces.std_msgs.msg import Header

from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_vision import Detection, VisionError
from mindgrasp_vision.ros_conversions import (
    depth_from_image,
    detection_to_msg,
    rgb_from_image,
)


def test_rgb_round_trip_and_bgr():
    rgb = np.random.default_rng(0).integers(0, 255, (6, 5, 3), dtype=np.uint8)
    msg = cv2_to_imgmsg(rgb, 'rgb8', Header(frame_id='camera'))
    assert (msg.encoding, msg.step, msg.height, msg.width) == ('rgb8', 15, 6, 5)
    assert np.array_equal(rgb_from_image(msg), rgb)
    bgr = Image(height=6, width=5, encoding='bgr8', step=15,
                data=np.ascontiguousarray(rgb[:, :, ::-1]).reshape(-1))
    assert np.array_equal(rgb_from_image(bgr), rgb)


def test_row_padding_is_skipped():
    rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
    padded = np.zeros((2, 12), np.uint8)
    padded[:, :9] = rgb.reshape(2, 9)
    msg = Image(height=2, width=3, encoding='rgb8', step=12, data=padded.reshape(-1))
    assert np.array_equal(rgb_from_image(msg), rgb)


def test_depth_encodings():
    depth = np.array([[0.5, 1.25], [2.0, np.nan]], np.float32)
    little = Image(height=2, width=2, encoding='32FC1', step=8, is_bigendian=0,
                   data=np.frombuffer(depth.astype('<f4').tobytes(), np.uint8))
    big = Image(height=2, width=2, encoding='32FC1', step=8, is_bigendian=1,
                data=np.frombuffer(depth.astype('>f4').tobytes(), np.uint8))
    for msg in (little, big):
        np.testing.assert_array_equal(depth_from_image(msg), depth)
    mm = np.array([[500, 1250], [2000, 0]], '<u2')
    msg = Image(height=2, width=2, encoding='16UC1', step=4,
                data=np.frombuffer(mm.tobytes(), np.uint8))
    np.testing.assert_array_equal(depth_from_image(msg), depth)


@pytest.mark.parametrize(('msg', 'func', 'match'), [
    (Image(height=2, width=2, encoding='mono8', step=2, data=np.zeros(4, np.uint8)),
     rgb_from_image, r"encoding 'mono8', expected 'rgb8'"),
    (Image(height=2, width=2, encoding='rgb8', step=6, data=np.zeros(5, np.uint8)),
     rgb_from_image, r'has step 6 and 5 bytes'),
    (Image(height=2, width=2, encoding='rgb8', step=6, data=np.zeros(12, np.uint8)),
     depth_from_image, r"encoding 'rgb8', expected '32FC1'"),
    (Image(height=0, width=2, encoding='rgb8', step=6), rgb_from_image, 'empty images'),
])
def test_bad_images_name_the_problem(msg, func, match):
    with pytest.raises(VisionError, match=match):
        func(msg)


def test_detection_message():
    d = Detection(colour='red', bbox=(1, 2, 3, 4), centre=(2.0, 3.5), pixel_count=12,
                  pixel_fraction=0.1, shape='cube', shape_confidence=0.9, score=0.4,
                  is_object_of_interest=True)
    m = detection_to_msg(DetectionMsg, RegionOfInterest, d)
    assert (m.bbox.x_offset, m.bbox.y_offset, m.bbox.width, m.bbox.height) == (1, 2, 3, 4)
    assert (m.colour, m.shape, m.pixel_count, m.is_object_of_interest) == ('red', 'cube', 12, True)
    assert m.centre_y == 3.5 and math.isnan(m.distance)
