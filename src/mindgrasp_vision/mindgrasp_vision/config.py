"""Vision parameters (the ``vision`` node's ROS parameters) and building a pipeline from them."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields

from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.detector import DEFAULT_COLOURS, ColourDetector
from mindgrasp_vision.pipeline import VisionPipeline
from mindgrasp_vision.ranking import ObjectOfInterestRanker

__all__ = ['DEFAULT_SHAPE_MODEL', 'VisionConfig']

#: the committed shape model (``shape_cnn.pt`` + ``.json`` in this package's ``models/``)
DEFAULT_SHAPE_MODEL = 'package://mindgrasp_vision/models/shape_cnn'


@dataclass
class VisionConfig:
    """All tunables of the vision node; defaults equal ``param/vision.yaml``.

    Units: pixels at 128x128 for ``min_pixels``/``morph_kernel``/``depth_median`` (scaled for
    larger images),
    metres for ``depth_edge``/``object_size``/``max_depth``, seconds for timeouts.
    """

    colour_names: list[str] = field(default_factory=lambda: list(DEFAULT_COLOURS))
    colour_ranges: dict[str, list[int]] = field(default_factory=lambda: {
        name: [r.hue_low, r.hue_high, r.sat_min, r.val_min] for name, r in DEFAULT_COLOURS.items()})
    min_pixels: int = 6
    morph_kernel: int = 3
    depth_edge: float = 0.03
    object_size: float = 0.05
    max_depth: float = 10.0
    depth_median: int = 3
    size_weight: float = 5.0
    hysteresis: float = 0.1
    switch_frames: int = 3
    match_radius: float = 0.15
    lost_frames: int = 10
    shape_model: str = DEFAULT_SHAPE_MODEL
    shape_min_fraction: float = 0.04
    shape_max_fraction: float = 0.35
    classify_states: list[int] = field(default_factory=lambda: [4])
    prediction_timeout: float = 1.0
    sync_tolerance: float = 0.02
    image_timeout: float = 2.0
    expected_width: int = 0
    expected_height: int = 0
    publish_overlay: bool = True
    duration: float = 0.0

    @classmethod
    def from_mapping(cls, values: Mapping[str, object]) -> VisionConfig:
        """From a flat mapping (``colour_ranges.red`` keys allowed); unknown keys are errors."""
        cfg = cls()
        names = {f.name for f in fields(cls)}
        ranges = dict(cfg.colour_ranges)
        for key, value in values.items():
            if key.startswith('colour_ranges.'):
                ranges[key.split('.', 1)[1]] = [int(v) for v in value]  # type: ignore[union-attr]
            elif key == 'colour_ranges':
                ranges.update({k: [int(x) for x in v] for k, v in dict(value).items()})
            elif key in names:
                setattr(cfg, key, value)
            else:
                msg = f'Unknown vision parameter {key!r}; known parameters are {sorted(names)}.'
                raise VisionError(msg)
        cfg.colour_ranges = ranges
        return cfg

    def flat(self) -> dict[str, object]:
        """Flat ROS parameter dict (``colour_ranges.<name>`` keys)."""
        out = {k: v for k, v in asdict(self).items() if k != 'colour_ranges'}
        for name, values in self.colour_ranges.items():
            out[f'colour_ranges.{name}'] = list(values)
        return out

    def build_detector(self) -> ColourDetector:
        """The :class:`ColourDetector` of these parameters."""
        return ColourDetector.from_parameters(
            self.colour_names, self.colour_ranges, min_pixels=int(self.min_pixels),
            morph_kernel=int(self.morph_kernel), depth_edge=float(self.depth_edge),
            object_size=float(self.object_size) if self.object_size > 0 else None,
            max_depth=float(self.max_depth))

    def build_ranker(self) -> ObjectOfInterestRanker:
        """The :class:`ObjectOfInterestRanker` of these parameters."""
        return ObjectOfInterestRanker(
            size_weight=float(self.size_weight), hysteresis=float(self.hysteresis),
            switch_frames=int(self.switch_frames), match_radius=float(self.match_radius),
            lost_frames=int(self.lost_frames))

    def load_classifier(self) -> object | None:
        """The shape classifier named by ``shape_model`` (None when it is '' or 'none')."""
        if self.shape_model.strip().lower() in ('', 'none'):
            return None
        from mindgrasp_vision.shape_cnn import ShapeClassifier

        return ShapeClassifier.load(self.shape_model)

    def build_pipeline(self, classifier: object | None = None) -> VisionPipeline:
        """A :class:`VisionPipeline` with these parameters (and a loaded classifier, if any)."""
        from mindgrasp_vision.depth import DepthFilter

        return VisionPipeline(self.build_detector(), self.build_ranker(), classifier,
                              shape_min_fraction=float(self.shape_min_fraction),
                              shape_max_fraction=float(self.shape_max_fraction),
                              depth_filter=DepthFilter(int(self.depth_median),
                                                       max_depth=float(self.max_depth)))
