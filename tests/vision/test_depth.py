"""Depth clean-up: validity mask, hole filling, median filter that keeps object borders."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.depth import DepthFilter, valid_depth


def scene() -> np.ndarray:
    depth = np.full((64, 64), 0.50, np.float32)
    depth[20:44, 20:44] = 0.40                  # a box 10 cm in front of the table
    return depth


def test_validity_mask() -> None:
    d = np.array([[0.5, np.nan, 0.0], [np.inf, -1.0, 12.0]], np.float32)
    np.testing.assert_array_equal(valid_depth(d, max_depth=10.0),
                                  [[True, False, False], [False, False, False]])


def test_small_holes_are_filled_large_ones_stay_invalid() -> None:
    depth = scene()
    holes = depth.copy()
    holes[10, 10] = np.nan                      # isolated drop-outs (NaN and 0 alike)
    holes[30, 30] = 0.0
    holes[50:60, 50:60] = np.nan                # a large unseen region
    out = DepthFilter(3)(holes)
    assert out[10, 10] == pytest.approx(0.50) and out[30, 30] == pytest.approx(0.40)
    assert np.isnan(out[52:58, 52:58]).all()    # nothing invented where nothing was seen
    assert out.dtype == np.float32 and out.shape == depth.shape


def test_median_removes_speckle_and_keeps_the_border() -> None:
    rng = np.random.default_rng(0)
    depth = scene()
    noisy = depth + rng.normal(0, 0.002, depth.shape).astype(np.float32)
    speckle = rng.random(depth.shape) < 0.03
    noisy[speckle] += 0.1                       # outliers
    out = DepthFilter(3)(noisy)
    err_in, err_out = np.abs(noisy - depth), np.abs(out - depth)
    # outliers gone (only the box's four corner pixels are rounded off, as a median does)
    assert np.count_nonzero(err_out > 0.02) <= 4 < np.count_nonzero(err_in > 0.02)
    assert err_out.std() < err_in.std() / 4
    # the 10 cm step stays a step: no pixel halfway between box and table
    row = out[32, 15:25]
    assert np.all((np.abs(row - 0.40) < 0.01) | (np.abs(row - 0.50) < 0.01))


def test_filter_off_and_bad_kernel() -> None:
    d = scene()
    d[5, 5] = 0.0
    out = DepthFilter(0)(d)
    assert np.isnan(out[5, 5]) and out[30, 30] == pytest.approx(0.40)
    with pytest.raises(VisionError, match=r"'depth_median' must be 0 or an odd number"):
        DepthFilter(4)
