"""Depth image clean-up for a real RGB-D camera: validity mask, hole filling and median filter.

A real depth camera reports no reading (NaN, or 0 in millimetre images) at object edges, on dark
or shiny surfaces and out of range, and its readings scatter with a spread that grows with the
distance squared. :class:`DepthFilter` turns such an image into one the detector and the shape CNN
can use: invalid pixels are masked, small holes (isolated drop-outs) are filled with the median of
their valid neighbours, and a median filter removes the speckle while keeping the depth jumps at
object borders (a mean would blur them). Large holes stay NaN: nothing is invented where the camera
saw nothing.
"""

from __future__ import annotations

import cv2
import numpy as np

from mindgrasp_vision._checks import VisionError, check_depth

__all__ = ['DepthFilter', 'valid_depth']


def valid_depth(depth: np.ndarray, max_depth: float = np.inf) -> np.ndarray:
    """Validity mask (H, W) bool of a depth image (m): finite, > 0 and below ``max_depth``."""
    with np.errstate(invalid='ignore'):
        return np.isfinite(depth) & (depth > 0) & (depth < max_depth)


class DepthFilter:
    """Median filter with a validity mask and hole filling.

    Parameters
    ----------
    kernel : int
        Side (px, odd; 0 or 1 disables the filter) of the median window at 128x128; scaled with
        the image size so a 640x480 image is filtered over the same field of view (OpenCV's float
        median supports 3 and 5; larger windows use 5).
    min_valid_fraction : float
        An invalid pixel is filled when at least this fraction of its window is valid; otherwise
        it stays NaN.
    max_depth : float
        Readings beyond this (m) are invalid.
    """

    def __init__(self, kernel: int = 3, min_valid_fraction: float = 0.5,
                 max_depth: float = 10.0) -> None:
        if kernel < 0 or (kernel > 1 and kernel % 2 == 0):
            msg = f"'depth_median' must be 0 or an odd number of pixels, got {kernel}; use 3."
            raise VisionError(msg)
        if not 0.0 < min_valid_fraction <= 1.0:
            msg = f"'min_valid_fraction' must be in (0, 1], got {min_valid_fraction}."
            raise VisionError(msg)
        self.kernel = int(kernel)
        self.min_valid_fraction = float(min_valid_fraction)
        self.max_depth = float(max_depth)

    def _side(self, height: int, width: int) -> int:
        scale = min(height, width) / 128.0
        side = max(self.kernel, round(self.kernel * scale) | 1)
        return min(side, 5)

    def __call__(self, depth: np.ndarray) -> np.ndarray:
        """The cleaned depth image, float32 (H, W) m, NaN where there is no usable reading."""
        depth = check_depth(depth)
        valid = valid_depth(depth, self.max_depth)
        if self.kernel <= 1:
            return np.where(valid, depth, np.float32(np.nan)).astype(np.float32)
        side = self._side(*depth.shape)
        box = (side, side)
        all_valid = bool(valid.all())
        if all_valid:
            filled = depth
        else:
            # fill each hole with the mean of its valid neighbours (normalised box filter), so
            # the median below sees plausible values instead of zeros
            v = valid.astype(np.float32)
            d = np.where(valid, depth, np.float32(0.0)).astype(np.float32)
            count = cv2.boxFilter(v, -1, box, normalize=False, borderType=cv2.BORDER_REPLICATE)
            total = cv2.boxFilter(d, -1, box, normalize=False, borderType=cv2.BORDER_REPLICATE)
            with np.errstate(invalid='ignore', divide='ignore'):
                mean = total / count
            filled = np.where(valid, depth, np.where(count > 0, mean, np.float32(0.0)))
            filled = filled.astype(np.float32)
        out = cv2.medianBlur(np.ascontiguousarray(filled, dtype=np.float32), side)
        if not all_valid:
            frac = count / float(side * side)
            keep = valid | (frac >= self.min_valid_fraction)
            out = np.where(keep, out, np.float32(np.nan)).astype(np.float32)
        return out
