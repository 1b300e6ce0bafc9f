"""Input validation shared by the vision classes: clear errors that name the problem and the fix."""

from __future__ import annotations

import numpy as np


class VisionError(ValueError):
    """Bad input or state in :mod:`mindgrasp_vision` (wrong image encoding/size, bad parameter)."""


def check_rgb(rgb: np.ndarray, name: str = 'rgb') -> np.ndarray:
    """Check an RGB image.

    Parameters
    ----------
    rgb : ndarray, shape (height, width, 3), dtype uint8
        Colour image, channels in R, G, B order (ROS encoding ``rgb8``).

    Returns
    -------
    rgb : ndarray, shape (height, width, 3), dtype uint8
        The same array (C-contiguous).
    """
    if not isinstance(rgb, np.ndarray):
        msg = (f"The colour image '{name}' must be a numpy array, got {type(rgb).__name__}; "
               'pass an (height, width, 3) uint8 array.')
        raise VisionError(msg)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        msg = (f"The colour image '{name}' has shape {rgb.shape}, expected (height, width, 3) "
               "(encoding 'rgb8'); convert RGBA/BGR/mono images to rgb8 first.")
        raise VisionError(msg)
    if rgb.dtype != np.uint8:
        msg = (f"The colour image '{name}' has dtype {rgb.dtype}, expected uint8 "
               "(encoding 'rgb8'); scale float images to 0-255 and cast to uint8 first.")
        raise VisionError(msg)
    if rgb.shape[0] < 8 or rgb.shape[1] < 8:
        msg = (f"The colour image '{name}' is {rgb.shape[1]}x{rgb.shape[0]} px, too small to "
               'segment; use an image of at least 8x8 px.')
        raise VisionError(msg)
    return np.ascontiguousarray(rgb)


def check_depth(depth: np.ndarray, shape: tuple[int, int] | None = None,
                name: str = 'depth') -> np.ndarray:
    """Check a depth image in metres.

    Parameters
    ----------
    depth : ndarray, shape (height, width), dtype float32
        Depth along the optical axis (m) (ROS encoding ``32FC1``). NaN/inf/<= 0 mark no reading.
    shape : tuple (height, width) | None
        Size the depth image must have (that of the colour image), or None for any size.

    Returns
    -------
    depth : ndarray, shape (height, width), dtype float32
    """
    if not isinstance(depth, np.ndarray):
        msg = (f"The depth image '{name}' must be a numpy array, got {type(depth).__name__}; "
               'pass an (height, width) float32 array in metres.')
        raise VisionError(msg)
    if depth.ndim == 3 and depth.shape[2] == 1:
        depth = depth[:, :, 0]
    if depth.ndim != 2:
        msg = (f"The depth image '{name}' has shape {depth.shape}, expected (height, width) "
               "(encoding '32FC1', metres).")
        raise VisionError(msg)
    if depth.dtype != np.float32:
        if depth.dtype == np.uint16:
            msg = (f"The depth image '{name}' has dtype uint16 (encoding '16UC1', millimetres); "
                   'convert it to float32 metres (depth / 1000) first.')
            raise VisionError(msg)
        if not np.issubdtype(depth.dtype, np.floating):
            msg = (f"The depth image '{name}' has dtype {depth.dtype}, expected float32 metres "
                   "(encoding '32FC1').")
            raise VisionError(msg)
        depth = depth.astype(np.float32)
    if shape is not None and depth.shape != tuple(shape):
        msg = (f"The depth image '{name}' is {depth.shape[1]}x{depth.shape[0]} px but the colour "
               f'image is {shape[1]}x{shape[0]} px; register the depth image to the colour '
               'camera (same size) first.')
        raise VisionError(msg)
    return np.ascontiguousarray(depth)
