"""One vision step per camera frame: detect, rank, classify the shape, draw the overlay.

:class:`VisionPipeline` is what the vision node runs on every frame; the controller's lock-step
experiments, the benchmark and the tests run the same object without ROS.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mindgrasp_vision._checks import VisionError, check_depth, check_rgb
from mindgrasp_vision.depth import DepthFilter
from mindgrasp_vision.detector import ColourDetector, Detection
from mindgrasp_vision.overlay import render_overlay
from mindgrasp_vision.ranking import ObjectOfInterestRanker

__all__ = ['FrameResult', 'VisionPipeline']


@dataclass
class FrameResult:
    """Vision output of one frame.

    Attributes
    ----------
    detections : list of Detection
        Ranked detections (``score``, ``is_object_of_interest`` and, for the object of interest
        once classified, ``shape`` / ``shape_confidence`` set).
    object_of_interest : int | None
        Index into ``detections``.
    focus : tuple (x, y)
        Ranking focus point (px).
    width, height : int
        Image size (px).
    classified : bool
        The shape CNN ran on this frame.
    """

    detections: list[Detection]
    object_of_interest: int | None
    focus: tuple[float, float]
    width: int
    height: int
    classified: bool = False
    shape_probabilities: np.ndarray | None = field(default=None, repr=False)

    @property
    def target(self) -> Detection | None:
        """The object of interest, or None."""
        if self.object_of_interest is None:
            return None
        return self.detections[self.object_of_interest]


class VisionPipeline:
    """Detector + ranker + (optional) shape classifier, frame by frame.

    Parameters
    ----------
    detector : ColourDetector | None
        Default :class:`ColourDetector` when None.
    ranker : ObjectOfInterestRanker | None
        Default :class:`ObjectOfInterestRanker` when None.
    classifier : ShapeClassifier | None
        Depth shape CNN; None disables shape classification.
    shape_min_fraction : float
        Classify automatically once the object of interest fills at least this fraction of the
        image (the view just before the final approach); values > 1 disable it.
    shape_max_fraction : float
        Never classify an object that fills more than this fraction of the image (closer than
        the training views, or between the fingers), even on request.
    depth_filter : DepthFilter | None
        Clean-up of the depth image before detection and classification (validity mask, hole
        filling, median); None uses the depth as it comes.
    """

    def __init__(self, detector: ColourDetector | None = None,
                 ranker: ObjectOfInterestRanker | None = None, classifier: object | None = None,
                 shape_min_fraction: float = 0.04, shape_max_fraction: float = 0.35,
                 depth_filter: DepthFilter | None = None) -> None:
        if shape_min_fraction < 0:
            msg = (f"'shape_min_fraction' must be >= 0, got {shape_min_fraction}; use a value "
                   '> 1 to classify only on request.')
            raise VisionError(msg)
        if not 0 < shape_max_fraction <= 1:
            msg = (f"'shape_max_fraction' must be in (0, 1], got {shape_max_fraction}; the "
                   'training views fill up to about 0.3 of the image.')
            raise VisionError(msg)
        self.detector = detector or ColourDetector()
        self.ranker = ranker or ObjectOfInterestRanker()
        self.classifier = classifier
        self.shape_min_fraction = float(shape_min_fraction)
        self.shape_max_fraction = float(shape_max_fraction)
        self.depth_filter = depth_filter
        self.reset()

    def reset(self) -> None:
        """Forget the object of interest and its shape (new trial)."""
        self.ranker.reset()
        self._shape_track = -1
        self._proba_sum: np.ndarray | None = None
        self._proba_n = 0

    def process(self, rgb: np.ndarray, depth: np.ndarray | None = None,
                mi_class: int | None = None, classify: bool = False) -> FrameResult:
        """Run one frame.

        Parameters
        ----------
        rgb : ndarray, shape (height, width, 3), dtype uint8
            Colour image (``rgb8``).
        depth : ndarray, shape (height, width), dtype float32 | None
            Registered depth image (m).
        mi_class : int | None
            Active MI class (0 left hand / 1 right hand shift the ranking focus).
        classify : bool
            Classify the object of interest's shape on this frame whatever its size.

        Returns
        -------
        result : FrameResult
        """
        rgb = check_rgb(rgb)
        height, width = rgb.shape[:2]
        if depth is not None:
            depth = check_depth(depth, shape=(height, width))
            if self.depth_filter is not None:
                depth = self.depth_filter(depth)
        detections = self.detector.detect(rgb, depth)
        ooi = self.ranker.rank(detections, width, height, mi_class)
        result = FrameResult(detections, ooi, self.ranker.focus(width, height, mi_class),
                             width, height)
        if ooi is None:
            return result
        target = detections[ooi]
        if self.ranker.track_id != self._shape_track:
            # a new object of interest: its shape is not known yet
            self._shape_track = self.ranker.track_id
            self._proba_sum, self._proba_n = None, 0
        want = (classify or target.pixel_fraction >= self.shape_min_fraction) \
            and target.pixel_fraction <= self.shape_max_fraction and not target.truncated
        if self.classifier is not None and depth is not None and want:
            from mindgrasp_vision.shape_cnn import preprocess_depth

            try:
                x = preprocess_depth(depth, target.bbox, target.mask, self.classifier.prep)
            except VisionError:
                x = None  # no valid depth on the object this frame: keep the last estimate
            if x is not None:
                proba = self.classifier.predict_proba(x[None])[0]
                self._proba_sum = proba if self._proba_sum is None else self._proba_sum + proba
                self._proba_n += 1
                result.classified = True
        if self._proba_sum is not None:
            # mean over the frames seen so far of this object: steadier than one frame
            mean = self._proba_sum / self._proba_n
            best = int(mean.argmax())
            target.shape = self.classifier.classes_[best]
            target.shape_confidence = float(mean[best])
            result.shape_probabilities = mean
        return result

    def overlay(self, rgb: np.ndarray, result: FrameResult) -> np.ndarray:
        """The AR overlay image of a processed frame, shape (height, width, 3), uint8."""
        return render_overlay(rgb, result.detections, result.focus)
