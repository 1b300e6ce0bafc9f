"""Helpers shared by the simulation tests."""

from __future__ import annotations

import numpy as np

# the original code's colour thresholds (../shared/reference/original-code-facts.md)
HIGH, LOW = 0.7 * 255, 0.3 * 255


def colour_mask(rgb: np.ndarray, colour: str) -> np.ndarray:
    """Pixels (H, W) bool of one of the task colours, by the original thresholds."""
    r, g, b = (rgb[..., i].astype(float) for i in range(3))
    if colour == 'red':
        return (r > HIGH) & (g < LOW) & (b < LOW)
    if colour == 'blue':
        return (r < LOW) & (g < LOW) & (b > HIGH)
    if colour == 'yellow':
        return (r > HIGH) & (g > HIGH) & (b < LOW)
    raise ValueError(colour)
