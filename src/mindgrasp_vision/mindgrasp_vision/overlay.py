"""Augmented-reality overlay of the eye-in-hand image: a green box round the object of interest."""

from __future__ import annotations

import math
from collections.abc import Sequence

import cv2
import numpy as np

from mindgrasp_vision._checks import check_rgb
from mindgrasp_vision.detector import Detection

__all__ = ['GREEN', 'render_overlay']

GREEN = (0, 255, 0)
_OTHER = (255, 255, 255)


def _label(det: Detection) -> str:
    text = det.colour if det.shape == 'unknown' else f'{det.colour} {det.shape}'
    if not math.isnan(det.distance):
        text += f' {det.distance:.2f}m'
    return text


def render_overlay(rgb: np.ndarray, detections: Sequence[Detection],
                   focus: tuple[float, float] | None = None, labels: bool = True) -> np.ndarray:
    """Draw the detections on a copy of the camera image.

    The object of interest (``is_object_of_interest``) gets a thick green box, the other
    detections a thin white one; labels give colour, shape (once classified) and distance.

    Parameters
    ----------
    rgb : ndarray, shape (height, width, 3), dtype uint8
        Camera image (``rgb8``); not modified.
    detections : sequence of Detection
        Ranked detections of this frame.
    focus : tuple (x, y) | None
        Ranking focus point (px) to mark with a small cross, or None.
    labels : bool
        Write the text labels.

    Returns
    -------
    overlay : ndarray, shape (height, width, 3), dtype uint8
    """
    out = check_rgb(rgb).copy()
    height = out.shape[0]
    scale = max(0.3, height / 640.0)
    thin = max(1, round(height / 256))
    thick = max(2, round(height / 128))
    # draw the object of interest last so that its box is on top
    for det in sorted(detections, key=lambda d: d.is_object_of_interest):
        x, y, w, h = det.bbox
        colour, width = (GREEN, thick) if det.is_object_of_interest else (_OTHER, thin)
        cv2.rectangle(out, (x, y), (x + w - 1, y + h - 1), colour, width)
        if labels:
            text_h = int(10 * scale / 0.3)  # label height (px) at this font scale
            below = (x, min(height - 2, y + h + text_h))
            org = (x, y - 3) if y > text_h + 2 else below
            cv2.putText(out, _label(det), org, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, 1,
                        cv2.LINE_AA)
    if focus is not None:
        fx, fy = round(focus[0]), round(focus[1])
        size = max(2, height // 40)
        cv2.drawMarker(out, (fx, fy), GREEN, cv2.MARKER_CROSS, size * 2, thin)
    return out
