"""Object-of-interest ranking: which detected object the user most likely wants.

Score of a detection (original MIndGrasp code): ``size_weight * pixel_fraction - d / width``, with
``d`` the distance (px) from the box centre to the focus point. The focus is the image centre, moved
to 1/4 (left hand MI) or 3/4 (right hand MI) of the width while such a prediction is active.
Hysteresis keeps the choice from flickering between objects of similar score: a challenger must beat
the current object of interest by ``hysteresis`` for ``switch_frames`` consecutive frames.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from mindgrasp_common.mi import MiClass
from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.detector import Detection

__all__ = ['LEFT_HAND', 'RIGHT_HAND', 'ObjectOfInterestRanker']

#: MI classes that shift the focus (mindgrasp_common.mi)
LEFT_HAND, RIGHT_HAND = int(MiClass.LEFT_HAND), int(MiClass.RIGHT_HAND)


@dataclass
class _Track:
    colour: str
    centre: tuple[float, float]
    missed: int = 0


class ObjectOfInterestRanker:
    """Rank detections and keep a stable object of interest across frames.

    Parameters
    ----------
    size_weight : float
        Weight of the pixel fraction in the score (5 in the original code).
    hysteresis : float
        Score margin a challenger needs over the current object of interest.
    switch_frames : int
        Consecutive frames the challenger must win before the choice changes (1 = at once).
    match_radius : float
        Largest centre motion between frames (fraction of the image width) for a detection to be
        taken as the same object.
    lost_frames : int
        Frames without any detection after which the remembered object of interest is forgotten.
    """

    def __init__(self, size_weight: float = 5.0, hysteresis: float = 0.1, switch_frames: int = 3,
                 match_radius: float = 0.15, lost_frames: int = 10) -> None:
        if size_weight < 0:
            msg = f"'size_weight' must be >= 0, got {size_weight}; the original code used 5."
            raise VisionError(msg)
        if hysteresis < 0:
            msg = f"'hysteresis' must be >= 0 (score units), got {hysteresis}; use 0 to disable."
            raise VisionError(msg)
        if switch_frames < 1:
            msg = f"'switch_frames' must be >= 1, got {switch_frames}; use 1 to switch at once."
            raise VisionError(msg)
        if not 0 < match_radius <= 1:
            msg = f"'match_radius' must be in (0, 1] (fraction of the width), got {match_radius}."
            raise VisionError(msg)
        self.size_weight = float(size_weight)
        self.hysteresis = float(hysteresis)
        self.switch_frames = int(switch_frames)
        self.match_radius = float(match_radius)
        self.lost_frames = int(lost_frames)
        self.reset()

    def reset(self) -> None:
        """Forget the current object of interest (e.g. when the controller returns to start)."""
        self._track: _Track | None = None
        self._challenger: _Track | None = None
        self._challenger_frames = 0
        #: counts the objects of interest chosen so far; changes whenever the choice changes
        self.track_id = getattr(self, 'track_id', 0) + 1

    @staticmethod
    def focus(width: int, height: int, mi_class: int | None = None) -> tuple[float, float]:
        """Focus point (px): image centre, or 1/4 / 3/4 of the width for left / right hand MI."""
        fx = {LEFT_HAND: 0.25, RIGHT_HAND: 0.75}.get(mi_class, 0.5) * width
        return fx, 0.5 * height

    def score(self, detection: Detection, width: int, height: int,
              mi_class: int | None = None) -> float:
        """Ranking score of one detection (higher is better)."""
        fx, fy = self.focus(width, height, mi_class)
        d = math.hypot(detection.centre[0] - fx, detection.centre[1] - fy)
        return self.size_weight * detection.pixel_fraction - d / width

    def _find(self, track: _Track, detections: Sequence[Detection], width: int) -> int | None:
        best, best_d = None, self.match_radius * width
        for i, det in enumerate(detections):
            if det.colour != track.colour:
                continue
            d = math.hypot(det.centre[0] - track.centre[0], det.centre[1] - track.centre[1])
            if d <= best_d:
                best, best_d = i, d
        return best

    def rank(self, detections: Sequence[Detection], width: int, height: int,
             mi_class: int | None = None) -> int | None:
        """Score the detections of one frame and choose the object of interest.

        Sets ``score`` and ``is_object_of_interest`` of every detection (in place).

        Parameters
        ----------
        detections : sequence of Detection
            This frame's detections.
        width, height : int
            Image size (px).
        mi_class : int | None
            Current MI class (0 left hand, 1 right hand, ...), None when no prediction is active.

        Returns
        -------
        index : int | None
            Index of the object of interest in ``detections``, None when there is none.
        """
        if width <= 0 or height <= 0:
            msg = f'The image size must be positive, got {width}x{height} px.'
            raise VisionError(msg)
        for det in detections:
            det.score = self.score(det, width, height, mi_class)
            det.is_object_of_interest = False
        if not detections:
            if self._track is not None:
                self._track.missed += 1
                if self._track.missed > self.lost_frames:
                    self.reset()
            return None
        best = max(range(len(detections)), key=lambda i: detections[i].score)
        current = None if self._track is None else self._find(self._track, detections, width)
        if current is None:
            chosen = best  # no incumbent, or it left the view: take the best at once
            self._challenger, self._challenger_frames = None, 0
        elif best == current or (detections[best].score
                                 <= detections[current].score + self.hysteresis):
            chosen = current
            self._challenger, self._challenger_frames = None, 0
        else:
            same = (self._challenger is not None
                    and self._find(self._challenger, [detections[best]], width) == 0)
            self._challenger_frames = self._challenger_frames + 1 if same else 1
            self._challenger = _Track(detections[best].colour, detections[best].centre)
            if self._challenger_frames >= self.switch_frames:
                chosen = best
                self._challenger, self._challenger_frames = None, 0
            else:
                chosen = current
        det = detections[chosen]
        det.is_object_of_interest = True
        if chosen != current:
            self.track_id += 1
        self._track = _Track(det.colour, det.centre)
        return chosen
