"""Vision parameters (the ``vision`` node's ROS parameters) and building a pipeline from them."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields

from mindgrasp_ros.params import param
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

    colour_names: list[str] = param(list(DEFAULT_COLOURS), 'colours to detect, in order',
                                    live=True)
    # HSV thresholds per colour, OpenCV ranges: [hue_low, hue_high, sat_min, val_min], hue 0..179
    # (hue_low > hue_high wraps round red), saturation/value 0..255
    colour_ranges: dict[str, list[int]] = param(
        {name: [r.hue_low, r.hue_high, r.sat_min, r.val_min]
         for name, r in DEFAULT_COLOURS.items()},
        'HSV range [hue_low, hue_high, sat_min, val_min] (OpenCV: hue 0..179, 0..255)',
        live=True)
    min_pixels: int = param(6, 'smallest object (at 128x128, scaled with the image area)',
                            unit='px', min=1, max=100000, live=True)
    morph_kernel: int = param(3, 'opening/closing kernel (at 128x128, odd; 0 = off)', unit='px',
                              min=0, max=51, live=True)
    depth_edge: float = param(0.03, 'depth jump that separates touching same-coloured objects',
                              unit='m', min=0.0, max=10.0, live=True)
    object_size: float = param(0.05, 'known object size for the pixel-size distance without '
                               'depth (0 = unknown)', unit='m', min=0.0, max=10.0, live=True)
    max_depth: float = param(10.0, 'depth readings beyond this are ignored', unit='m',
                             min=0.01, max=1000.0, live=True)
    depth_median: int = param(3, 'median filter of the depth image (at 128x128, odd; 0 = off)',
                              unit='px', min=0, max=51, live=True)
    # object-of-interest ranking: score = size_weight * pixel_fraction - distance_to_focus / width
    size_weight: float = param(5.0, 'weight of the pixel fraction in the ranking score', min=0.0,
                               max=1000.0, live=True)
    hysteresis: float = param(0.1, 'score margin a challenger needs over the current choice',
                              min=0.0, max=10.0, live=True)
    switch_frames: int = param(3, 'consecutive frames a challenger must lead', min=1, max=1000,
                               live=True)
    match_radius: float = param(0.15, 'max centre motion between frames of the same object '
                                '(fraction of the width)', min=0.0, max=1.0, live=True)
    lost_frames: int = param(10, 'frames without detections before the choice is forgotten',
                             min=1, max=10000, live=True)
    shape_model: str = param(DEFAULT_SHAPE_MODEL, 'depth shape CNN (.pt + .json, a path or a '
                             "package:// URI); '' or none disables shapes")
    shape_min_fraction: float = param(0.04, 'classify once the object of interest fills this '
                                      'image fraction', min=0.0, max=1.0, live=True)
    shape_max_fraction: float = param(0.35, '... but not beyond this (closer than the training '
                                      'views)', min=0.0, max=1.0, live=True)
    classify_states: list[int] = param([4], 'always classify while /fsm/state is in these states '
                                       '(4 = final approach)', live=True)
    prediction_timeout: float = param(1.0, 'a left/right MI prediction shifts the focus for this '
                                      'long', unit='s', min=0.0, max=60.0, live=True)
    sync_tolerance: float = param(0.02, 'colour/depth stamps closer than this belong to one '
                                  'frame', unit='s', min=0.0, max=1.0, live=True)
    image_timeout: float = param(2.0, 'log an error when no colour image came for this long '
                                 '(0 = off)', unit='s', min=0.0, max=600.0, live=True)
    expected_width: int = param(0, 'reject images of another width (0 = any)', unit='px', min=0,
                                max=100000, live=True)
    expected_height: int = param(0, 'reject images of another height (0 = any)', unit='px',
                                 min=0, max=100000, live=True)
    publish_overlay: bool = param(True, 'publish /vision/overlay', live=True)

    def __post_init__(self) -> None:
        """Check what the detector and ranker will be built from (a bad colour range)."""
        self.build_detector()
        self.build_ranker()

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
