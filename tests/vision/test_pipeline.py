"""VisionPipeline on simulator frames: detection, ranking, shape classification per object."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_common.resources import resource_path
from mindgrasp_vision import VisionError
from mindgrasp_vision.params import VisionConfig
from mindgrasp_vision.pipeline import VisionPipeline
from mindgrasp_vision.shape_cnn import SHAPES


class _FixedClassifier:
    """Stands in for the CNN where only the pipeline's bookkeeping is under test."""

    classes_ = list(SHAPES)

    def __init__(self, proba: list[float]) -> None:
        from mindgrasp_vision.shape_cnn import Preprocessing

        self.prep = Preprocessing()
        self.proba = np.array(proba, np.float32)
        self.calls = 0

    def predict_proba(self, x: np.ndarray) -> np.ndarray:
        assert x.shape == (1, 128, 128)
        self.calls += 1
        return self.proba[None]


def test_three_objects_left_right_and_overlay(view, detector):
    objects = [{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.12]},
               {'shape': 'sphere', 'colour': 'yellow', 'position': [0.45, 0.0]},
               {'shape': 'cylinder', 'colour': 'blue', 'position': [0.45, -0.12]}]
    rgb, depth = view(objects, (0.45, 0.0, 0.025), distance=0.4, elevation_deg=45)
    pipe = VisionPipeline(detector, classifier=None)
    result = pipe.process(rgb, depth)
    assert len(result.detections) == 3 and result.target.colour == 'yellow'
    assert result.focus == (64.0, 64.0)
    # the user imagines the left hand: the object on the robot's left (+y, image left)
    for _ in range(3):
        result = pipe.process(rgb, depth, mi_class=0)
    assert result.target.colour == 'red' and result.focus == (32.0, 64.0)
    pipe.reset()
    assert pipe.process(rgb, depth, mi_class=1).target.colour == 'blue'
    overlay = pipe.overlay(rgb, result)
    assert overlay.shape == rgb.shape and (overlay != rgb).any()


def test_shape_is_classified_when_large_or_requested_and_averaged(view, detector):
    rgb, depth = view([{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.0]}],
                      (0.45, 0.0, 0.025), distance=0.4, elevation_deg=50)
    clf = _FixedClassifier([0.2, 0.7, 0.1])
    pipe = VisionPipeline(detector, classifier=clf, shape_min_fraction=0.5)
    result = pipe.process(rgb, depth)
    assert not result.classified and result.target.shape == 'unknown' and clf.calls == 0
    result = pipe.process(rgb, depth, classify=True)
    assert result.classified and result.target.shape == 'cylinder'
    assert result.target.shape_confidence == pytest.approx(0.7)
    # the shape stays with the object on later frames, and frames are averaged
    clf.proba = np.array([0.9, 0.05, 0.05], np.float32)
    result = pipe.process(rgb, depth)
    assert not result.classified and result.target.shape == 'cylinder'
    result = pipe.process(rgb, depth, classify=True)
    assert result.target.shape == 'cube'
    assert result.target.shape_confidence == pytest.approx((0.2 + 0.9) / 2)
    # large enough: classified without request; no depth: no classification
    pipe.shape_min_fraction = 0.0
    pipe.reset()
    assert pipe.process(rgb, depth).classified
    assert not pipe.process(rgb, None).classified
    # too close (fills more than shape_max_fraction): not even on request
    pipe.shape_max_fraction = 0.001
    assert not pipe.process(rgb, depth, classify=True).classified


def test_config_builds_the_pipeline_and_rejects_unknown_parameters():
    cfg = VisionConfig.from_mapping({'hysteresis': 0.2, 'colour_ranges.red': [0, 10, 90, 30],
                                     'shape_model': 'none'})
    pipe = cfg.build_pipeline(cfg.load_classifier())
    assert pipe.ranker.hysteresis == 0.2 and pipe.classifier is None
    assert pipe.detector.colours['red'].sat_min == 90
    with pytest.raises(VisionError, match="Unknown vision parameter 'hysterisis'"):
        VisionConfig.from_mapping({'hysterisis': 0.2})
    with pytest.raises(VisionError, match='does not exist; train one'):
        VisionConfig(shape_model='/nonexistent/model').load_classifier()


def test_parameter_file_matches_the_defaults():

    import yaml

    path = resource_path('mindgrasp_vision', 'param', 'vision.yaml')
    params = yaml.safe_load(path.read_text())['vision']['ros__parameters']
    assert VisionConfig.from_mapping(params) == VisionConfig()
