"""cv2_to_imgmsg: one builder of sensor_msgs/Image for every node."""

from __future__ import annotations

import array
import re

import numpy as np
import pytest
from mindgrasp_ros.interfaces.std_msgs.msg import Header

from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_ros.typesupport import deserialize, serialize


def test_colour_and_depth_keep_their_pixels_through_the_wire() -> None:
    rng = np.random.default_rng(0)
    rgb = rng.integers(0, 256, (4, 5, 3), dtype=np.uint8)
    depth = rng.uniform(0.1, 2.0, (4, 5)).astype(np.float32)
    colour = cv2_to_imgmsg(rgb, 'rgb8', Header(frame_id='camera'))
    depth_msg = cv2_to_imgmsg(depth, '32FC1')
    assert (colour.height, colour.width, colour.step, colour.header.frame_id) == (4, 5, 15,
                                                                                  'camera')
    assert (depth_msg.encoding, depth_msg.step) == ('32FC1', 20)
    back = deserialize(serialize(colour), 'sensor_msgs/msg/Image')
    assert np.array_equal(np.asarray(back.data, np.uint8).reshape(4, 5, 3), rgb)
    back = deserialize(serialize(depth_msg), 'sensor_msgs/msg/Image')
    assert np.array_equal(np.frombuffer(np.asarray(back.data, np.uint8).tobytes(), '<f4')
                          .reshape(4, 5), depth)


def test_the_data_is_handed_over_as_a_byte_array() -> None:
    # the real rclpy's Image.data setter takes array.array('B') as it is and converts anything
    # else element by element (25-75 ms a camera frame, the simulator's 0.3 s stalls)
    frame = np.zeros((128, 128, 3), np.uint8)
    msg = cv2_to_imgmsg(frame, 'rgb8')
    data = msg.data
    assert isinstance(data, array.array) or np.asarray(data).dtype == np.uint8
    assert len(data) == 128 * 128 * 3


@pytest.mark.parametrize(('image', 'encoding', 'fix'), [
    (np.zeros((4, 5)), 'rgb8', 'shape (height, width, 3)'),
    (np.zeros((4, 5, 3)), 'bgr16', 'use one of'),
])
def test_a_wrong_encoding_or_shape_is_one_line(image: np.ndarray, encoding: str,
                                               fix: str) -> None:
    with pytest.raises(ValueError, match=re.escape(fix)):
        cv2_to_imgmsg(image, encoding)
