"""AR overlay: a green box round the object of interest."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_vision import Detection, VisionError, render_overlay
from mindgrasp_vision.overlay import GREEN


def _det(colour: str, bbox: tuple[int, int, int, int], ooi: bool) -> Detection:
    x, y, w, h = bbox
    return Detection(colour=colour, bbox=bbox, centre=(x + (w - 1) / 2, y + (h - 1) / 2),
                     pixel_count=w * h, pixel_fraction=w * h / 128 ** 2, distance=0.3,
                     is_object_of_interest=ooi)


def test_green_box_round_the_object_of_interest_only():
    rgb = np.full((128, 128, 3), 120, np.uint8)
    before = rgb.copy()
    dets = [_det('red', (20, 60, 20, 20), False), _det('blue', (80, 60, 20, 20), True)]
    out = render_overlay(rgb, dets, focus=(64, 64), labels=False)
    assert np.array_equal(rgb, before), 'the input image must not be modified'
    green = np.all(out == GREEN, axis=2)
    # the box outline of the object of interest is green, its inside untouched
    assert green[60, 80:100].all() and green[79, 80:100].all() and green[60:80, 80].all()
    assert not green[65:75, 85:95].any()
    # the other detection gets a thin white box, no green
    assert not green[55:85, 15:45].any()
    assert np.all(out[60, 20:40] == 255)


def test_labels_are_drawn():
    rgb = np.full((128, 128, 3), 120, np.uint8)
    plain = render_overlay(rgb, [_det('red', (40, 40, 30, 30), True)], labels=False)
    labelled = render_overlay(rgb, [_det('red', (40, 40, 30, 30), True)], labels=True)
    assert (plain != labelled).any(axis=2)[:40].sum() > 20   # text above the box


def test_large_image_and_bad_input():
    rgb = np.zeros((480, 640, 3), np.uint8)
    out = render_overlay(rgb, [_det('red', (100, 100, 50, 50), True)])
    assert out.shape == (480, 640, 3)
    with pytest.raises(VisionError, match='rgb8'):
        render_overlay(np.zeros((10, 10), np.uint8), [])
