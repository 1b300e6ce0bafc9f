"""Conversions between sensor_msgs/Image and numpy, and Detection -> mindgrasp_msgs (no rclpy).

Works on any message object with the ROS field names (our runtime's classes or rclpy's).
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from mindgrasp_ros.topics import COLOR_IMAGE, DEPTH_IMAGE
from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.detector import Detection

__all__ = ['depth_from_image', 'detection_to_msg', 'rgb_from_image']


def _rows(msg: object, channels: int, itemsize: int, topic: str) -> np.ndarray:
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    if h <= 0 or w <= 0:
        msg_ = f'The image on {topic} is {w}x{h} px; the camera publishes empty images.'
        raise VisionError(msg_)
    data = np.asarray(msg.data, dtype=np.uint8).reshape(-1)
    row = w * channels * itemsize
    if step < row or data.size < step * h:
        msg_ = (f"The image on {topic} ({w}x{h} px, encoding '{msg.encoding}') has step {step} "
                f'and {data.size} bytes, expected step >= {row} and {row * h} bytes; the '
                'publisher fills height/width/step/data inconsistently.')
        raise VisionError(msg_)
    return data[:step * h].reshape(h, step)[:, :row]


def rgb_from_image(msg: object, topic: str = COLOR_IMAGE.name) -> np.ndarray:
    """Colour image, shape (height, width, 3) uint8 RGB, from an ``rgb8`` or ``bgr8`` Image."""
    enc = str(msg.encoding).lower()
    if enc not in ('rgb8', 'bgr8'):
        msg_ = (f"The image on {topic} has encoding '{msg.encoding}', expected 'rgb8' (or "
                "'bgr8'); configure the camera driver for rgb8 colour images.")
        raise VisionError(msg_)
    rows = _rows(msg, 3, 1, topic)
    rgb = rows.reshape(int(msg.height), int(msg.width), 3)
    if enc == 'bgr8':
        return cv2.cvtColor(rgb, cv2.COLOR_BGR2RGB)
    return np.ascontiguousarray(rgb)


def depth_from_image(msg: object, topic: str = DEPTH_IMAGE.name) -> np.ndarray:
    """Depth image, shape (height, width) float32 m, from a ``32FC1`` or ``16UC1`` (mm) Image."""
    enc = str(msg.encoding).upper()
    h, w = int(msg.height), int(msg.width)
    if enc == '32FC1':
        rows = _rows(msg, 1, 4, topic)
        dtype = np.dtype('>f4' if msg.is_bigendian else '<f4')
        return np.ascontiguousarray(rows).view(dtype).reshape(h, w).astype(np.float32)
    if enc == '16UC1':
        rows = _rows(msg, 1, 2, topic)
        dtype = np.dtype('>u2' if msg.is_bigendian else '<u2')
        mm = np.ascontiguousarray(rows).view(dtype).reshape(h, w).astype(np.float32)
        mm[mm == 0] = np.nan  # 0 = no reading in the 16UC1 convention
        return mm / 1000.0
    msg_ = (f"The depth image on {topic} has encoding '{msg.encoding}', expected '32FC1' "
            "(metres) or '16UC1' (millimetres); configure the depth camera accordingly.")
    raise VisionError(msg_)


def detection_to_msg(detection_cls: type, roi_cls: type, det: Detection) -> object:
    """A mindgrasp_msgs/Detection of a :class:`Detection`."""
    x, y, w, h = det.bbox
    return detection_cls(
        colour=det.colour, shape=det.shape, shape_confidence=float(det.shape_confidence),
        bbox=roi_cls(x_offset=x, y_offset=y, width=w, height=h, do_rectify=False),
        centre_x=float(det.centre[0]), centre_y=float(det.centre[1]),
        pixel_count=int(det.pixel_count), pixel_fraction=float(det.pixel_fraction),
        distance=float(det.distance) if not math.isnan(det.distance) else math.nan,
        score=float(det.score), is_object_of_interest=bool(det.is_object_of_interest))
