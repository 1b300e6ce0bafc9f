"""mindgrasp_vision: eye-in-hand vision of MIndGrasp.

Layers: ROS-free algorithms (:mod:`~mindgrasp_vision.detector` colour segmentation,
:mod:`~mindgrasp_vision.ranking` object-of-interest choice, :mod:`~mindgrasp_vision.overlay` AR
image, :mod:`~mindgrasp_vision.shape_cnn` depth shape classifier, :mod:`~mindgrasp_vision.pipeline`
all of them per frame), the simulator data set (:mod:`~mindgrasp_vision.dataset`), the
``mindgrasp train vision`` command (:mod:`~mindgrasp_vision.commands.train_vision`) and the ROS node
(:mod:`~mindgrasp_vision.vision_node`).

Heavy modules (torch, the simulator) are imported only when used.
"""

from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.detector import (
    DEFAULT_COLOURS,
    CameraModel,
    ColourDetector,
    ColourRange,
    Detection,
)
from mindgrasp_vision.overlay import render_overlay
from mindgrasp_vision.ranking import LEFT_HAND, RIGHT_HAND, ObjectOfInterestRanker

__all__ = [
    'DEFAULT_COLOURS',
    'LEFT_HAND',
    'RIGHT_HAND',
    'CameraModel',
    'ColourDetector',
    'ColourRange',
    'Detection',
    'ObjectOfInterestRanker',
    'VisionError',
    'render_overlay',
]
