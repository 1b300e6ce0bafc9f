"""Graz-BCI screen rendered with OpenCV: fixation cross, class arrow, classifier feedback bar.

The arrow and the feedback bar point the same way for a class: left hand left, right hand right,
both hands up, both feet down. No ROS imports; the Graz node publishes the frames as
sensor_msgs/Image (rgb8) and tests inspect the pixels.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from mindgrasp_trainer.protocol import CLASS_NAMES, NO_CLASS, PromptEvent, TrainerError

__all__ = ['ARROW_COLOUR', 'BAR_COLOUR', 'DIRECTIONS', 'FEEDBACK_MODES', 'render_display']

#: Unit screen direction (x right, y down) of each class's arrow and feedback bar.
DIRECTIONS: dict[int, tuple[int, int]] = {0: (-1, 0), 1: (1, 0), 2: (0, -1), 3: (0, 1)}
ARROW_COLOUR = (220, 30, 30)  # rgb
BAR_COLOUR = (40, 200, 60)
CROSS_COLOUR = (255, 255, 255)
FEEDBACK_MODES = ('off', 'move', 'always')


def render_display(
    event: PromptEvent | None,
    prediction: tuple[int, float] | None = None,
    width: int = 480,
    height: int = 360,
    feedback: str = 'move',
    max_certainty: float = 1.0,
) -> np.ndarray:
    """Draw one frame of the Graz screen.

    Parameters
    ----------
    event : PromptEvent or None
        The current prompt phase; None before the first (blank screen).
    prediction : (class_index, certainty) or None
        Latest classifier output; the bar length is ``certainty / max_certainty`` of the space
        between the centre and the edge (clipped to 1).
    width, height : int
        Frame size (pixels).
    feedback : {'off', 'move', 'always'}
        When to draw the feedback bar: never, during the imagery (``move``) phase, or always.
    max_certainty : float
        Certainty that fills the bar.

    Returns
    -------
    frame : ndarray of uint8, shape (height, width, 3), RGB
    """
    if width < 32 or height < 32:
        msg = f'The display size {width}x{height} px is too small; use at least 32x32 pixels.'
        raise TrainerError(msg)
    if feedback not in FEEDBACK_MODES:
        msg = f"'feedback' is {feedback!r}; use one of {', '.join(FEEDBACK_MODES)}."
        raise TrainerError(msg)
    if not (math.isfinite(max_certainty) and max_certainty > 0):
        msg = f"'max_certainty' must be a positive number; {max_certainty} is invalid."
        raise TrainerError(msg)
    img = np.zeros((height, width, 3), np.uint8)
    if event is None:
        return img
    cx, cy = width // 2, height // 2
    reach = min(width, height) // 2 - 8  # pixels from centre to the drawing's edge
    thick = max(2, min(width, height) // 60)
    if event.phase in ('fixation', 'cue', 'move'):
        arm = reach // 3
        cv2.line(img, (cx - arm, cy), (cx + arm, cy), CROSS_COLOUR, thick)
        cv2.line(img, (cx, cy - arm), (cx, cy + arm), CROSS_COLOUR, thick)
    show_bar = feedback == 'always' or (feedback == 'move' and event.phase == 'move')
    if show_bar and prediction is not None and event.phase != 'end':
        k, certainty = int(prediction[0]), float(prediction[1])
        if k in DIRECTIONS and math.isfinite(certainty):
            dx, dy = DIRECTIONS[k]
            length = round(reach * min(max(certainty / max_certainty, 0.0), 1.0))
            half = max(3, reach // 10)
            x0, y0 = cx + dx * half, cy + dy * half
            x1, y1 = cx + dx * length, cy + dy * length
            px, py = abs(dy) * half, abs(dx) * half  # bar thickness across its direction
            if length > half:
                cv2.rectangle(
                    img,
                    (min(x0, x1) - px, min(y0, y1) - py),
                    (max(x0, x1) + px, max(y0, y1) + py),
                    BAR_COLOUR,
                    -1,
                )
            label = f'{CLASS_NAMES[k]} {certainty:.2f}'
            cv2.putText(img, label, (8, height - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.45,
                        BAR_COLOUR, 1, cv2.LINE_AA)
    if event.phase == 'cue' and event.class_index != NO_CLASS:
        dx, dy = DIRECTIONS[event.class_index]
        start = (cx - dx * reach // 2, cy - dy * reach // 2)
        tip = (cx + dx * reach, cy + dy * reach)
        cv2.arrowedLine(img, start, tip, ARROW_COLOUR, 3 * thick, cv2.LINE_AA, tipLength=0.3)
    if event.phase == 'end':
        cv2.putText(img, 'end', (cx - 30, cy + 10), cv2.FONT_HERSHEY_SIMPLEX, 1.0,
                    CROSS_COLOUR, 2, cv2.LINE_AA)
    return img
