"""numpy images to ``sensor_msgs/Image``, named after cv_bridge's ``cv2_to_imgmsg``.

One place builds every image message, because of the real rclpy: its generated ``Image.data``
setter takes an ``array.array('B')`` as it is but converts any other sequence element by
element. A 128x128 colour and depth pair handed over as numpy arrays took 25-75 ms per frame,
which stalled the simulator 0.3 s at a time on a busy 2-core machine (issue 39); as
``array.array`` it takes microseconds. The runtime without rclpy reads the same buffer.
"""

from __future__ import annotations

import array

import numpy as np

from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

#: encoding -> (numpy dtype of a pixel channel, channels); little-endian as the machine sends
ENCODINGS: dict[str, tuple[str, int]] = {
    'rgb8': ('u1', 3),
    'mono8': ('u1', 1),
    '32FC1': ('<f4', 1),
    '16UC1': ('<u2', 1),
}


def cv2_to_imgmsg(image: np.ndarray, encoding: str, header: object | None = None) -> Image:
    """A ``sensor_msgs/Image`` of ``image`` (shape (height, width) or (height, width,
    channels), any numeric dtype; cast to the encoding's dtype).

    Raises ``ValueError`` for an unknown encoding or a shape that does not fit it."""
    if encoding not in ENCODINGS:
        msg = f"Unknown image encoding '{encoding}'; use one of {', '.join(ENCODINGS)}."
        raise ValueError(msg)
    dtype, channels = ENCODINGS[encoding]
    pixels = np.ascontiguousarray(image, dtype=dtype)
    if pixels.ndim == 2 and channels == 1:
        pixels = pixels[:, :, None]
    if pixels.ndim != 3 or pixels.shape[2] != channels:
        msg = (f'An {encoding} image has shape (height, width, {channels}), not '
               f'{image.shape}.')
        raise ValueError(msg)
    h, w = pixels.shape[:2]
    data = array.array('B')
    data.frombytes(memoryview(pixels).cast('B'))     # one copy of the pixels
    msg_ = Image(height=h, width=w, encoding=encoding, is_bigendian=0,
                 step=w * channels * pixels.itemsize, data=data)
    if header is not None:
        msg_.header = header
    return msg_
