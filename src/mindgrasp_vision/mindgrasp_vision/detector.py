"""Per-object colour segmentation of an eye-in-hand RGB-D frame.

The original MIndGrasp code thresholded RGB values and merged every pixel of one colour into one
box, so two objects of the same colour became one. Here each colour is thresholded in HSV (robust to
the shading of curved surfaces), cleaned with a morphological opening and closing, split at depth
discontinuities (so a same-coloured object partly hiding another stays separate) and labelled into
connected components: one :class:`Detection` per object.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from mindgrasp_common.types import CameraModel
from mindgrasp_vision._checks import VisionError, check_depth, check_rgb

__all__ = [
    'DEFAULT_COLOURS',
    'CameraModel',
    'ColourDetector',
    'ColourRange',
    'Detection',
]


@dataclass(frozen=True)
class ColourRange:
    """HSV threshold of one object colour (OpenCV ranges: hue 0-179, saturation/value 0-255).

    ``hue_low > hue_high`` means the range wraps round 180 (red: 170..179 and 0..10).
    """

    hue_low: int
    hue_high: int
    sat_min: int = 100
    val_min: int = 50

    def __post_init__(self) -> None:
        for name in ('hue_low', 'hue_high'):
            value = getattr(self, name)
            if not 0 <= value <= 179:
                msg = (f"The HSV threshold '{name}' is {value}, outside OpenCV's hue range; "
                       'use a value in 0..179 (degrees / 2).')
                raise VisionError(msg)
        for name in ('sat_min', 'val_min'):
            value = getattr(self, name)
            if not 0 <= value <= 255:
                msg = f"The HSV threshold '{name}' is {value}; use a value in 0..255."
                raise VisionError(msg)

    @classmethod
    def from_sequence(cls, values: Sequence[int]) -> ColourRange:
        """Build from ``[hue_low, hue_high, sat_min, val_min]`` (the ROS parameter form)."""
        if len(values) != 4:
            msg = (f'A colour range needs 4 numbers [hue_low, hue_high, sat_min, val_min], got '
                   f'{list(values)}; fix the colour_ranges parameter.')
            raise VisionError(msg)
        return cls(*(int(v) for v in values))

    def mask(self, hsv: np.ndarray) -> np.ndarray:
        """Binary mask (uint8 0/255, shape (height, width)) of the pixels of ``hsv`` in range."""
        if self.hue_low <= self.hue_high:
            return cv2.inRange(hsv, (self.hue_low, self.sat_min, self.val_min),
                               (self.hue_high, 255, 255))
        low = cv2.inRange(hsv, (self.hue_low, self.sat_min, self.val_min), (179, 255, 255))
        high = cv2.inRange(hsv, (0, self.sat_min, self.val_min), (self.hue_high, 255, 255))
        return cv2.bitwise_or(low, high)


#: Default thresholds for the saturated red, yellow and blue objects of the MIndGrasp scenes.
DEFAULT_COLOURS: dict[str, ColourRange] = {
    'red': ColourRange(170, 8, 120, 40),
    'yellow': ColourRange(20, 35, 120, 60),
    'blue': ColourRange(105, 130, 120, 40),
}


@dataclass
class Detection:
    """One coloured object found in a frame.

    Attributes
    ----------
    colour : str
        Colour name (a key of the detector's colour table: red, yellow, blue).
    bbox : tuple of int (x, y, w, h)
        Bounding box (px), x right, y down from the top-left corner.
    centre : tuple of float (x, y)
        Bounding-box midpoint (px), as in the original MIndGrasp code.
    pixel_count : int
        Object pixels in the component.
    pixel_fraction : float
        ``pixel_count`` / image area.
    distance : float
        Camera-to-object distance along the optical axis (m): the median depth of the object's
        pixels, or estimated from pixel size for objects of known size; NaN when unknown.
    distance_source : str
        'depth', 'size' or 'none'.
    position : tuple of float (x, y, z) | None
        Object centre in the camera optical frame (m; x right, y down, z forward) when intrinsics
        and a distance are known.
    truncated : bool
        The box touches the image border (the object may be cut off).
    shape, shape_confidence : str, float
        Shape from the depth CNN ('unknown', 0.0 until classified).
    score, is_object_of_interest : float, bool
        Set by :class:`mindgrasp_vision.ranking.ObjectOfInterestRanker`.
    mask : ndarray, shape (h, w), dtype bool
        The object's pixels inside ``bbox``.
    """

    colour: str
    bbox: tuple[int, int, int, int]
    centre: tuple[float, float]
    pixel_count: int
    pixel_fraction: float
    distance: float = math.nan
    distance_source: str = 'none'
    position: tuple[float, float, float] | None = None
    truncated: bool = False
    shape: str = 'unknown'
    shape_confidence: float = 0.0
    score: float = 0.0
    is_object_of_interest: bool = False
    mask: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def centre_x(self) -> float:
        """Bounding-box midpoint x (px)."""
        return self.centre[0]

    @property
    def centre_y(self) -> float:
        """Bounding-box midpoint y (px)."""
        return self.centre[1]

    @property
    def label(self) -> str:
        """'<colour> <shape>' as used in FsmState and GraspResult."""
        return f'{self.colour} {self.shape}'

    def full_mask(self, height: int, width: int) -> np.ndarray:
        """The object's pixels as a full-image bool mask, shape (height, width)."""
        out = np.zeros((height, width), dtype=bool)
        x, y, w, h = self.bbox
        if self.mask is not None:
            out[y:y + h, x:x + w] = self.mask
        else:
            out[y:y + h, x:x + w] = True
        return out

    def copy(self, **changes: object) -> Detection:
        """A shallow copy with some fields changed."""
        return replace(self, **changes)


class ColourDetector:
    """Find red, yellow and blue objects (one detection per object) in an RGB(-D) frame.

    Parameters
    ----------
    colours : mapping of str to ColourRange | None
        HSV thresholds per colour name; None for :data:`DEFAULT_COLOURS`.
    min_pixels : int
        Smallest object kept (px at 128x128; scaled with the image area for larger images).
    morph_kernel : int
        Side (px, odd) of the square kernel of the opening/closing at 128x128 (scaled likewise);
        0 disables morphology.
    depth_edge : float
        Depth jump (m) between neighbouring pixels that separates two touching objects of the same
        colour; 0 disables the split.
    object_size : float | None
        Known object size (m) for the pixel-size distance estimate used when no depth is given.
    intrinsics : CameraModel | None
        Camera model, used for ``position`` and the pixel-size distance.
    max_depth : float
        Depth readings beyond this (m) count as no reading.
    min_split_fraction : float
        A depth split keeps only parts with at least this fraction of the component's pixels
        (smaller parts are grazing faces of the same object).
    """

    def __init__(self, colours: Mapping[str, ColourRange] | None = None, *, min_pixels: int = 6,
                 morph_kernel: int = 3, depth_edge: float = 0.03,
                 object_size: float | None = None, intrinsics: CameraModel | None = None,
                 max_depth: float = 10.0, min_split_fraction: float = 0.15) -> None:
        self.colours = dict(DEFAULT_COLOURS if colours is None else colours)
        if not self.colours:
            msg = 'The detector needs at least one colour range; pass e.g. DEFAULT_COLOURS.'
            raise VisionError(msg)
        if min_pixels < 1:
            msg = f"'min_pixels' must be >= 1, got {min_pixels}; use e.g. 6."
            raise VisionError(msg)
        if morph_kernel < 0 or (morph_kernel and morph_kernel % 2 == 0):
            msg = f"'morph_kernel' must be 0 or an odd number of pixels, got {morph_kernel}."
            raise VisionError(msg)
        if depth_edge < 0:
            msg = f"'depth_edge' must be >= 0 m, got {depth_edge}; use 0 to disable the split."
            raise VisionError(msg)
        if object_size is not None and object_size <= 0:
            msg = f"'object_size' must be > 0 m or None, got {object_size}."
            raise VisionError(msg)
        self.min_pixels = int(min_pixels)
        self.morph_kernel = int(morph_kernel)
        self.depth_edge = float(depth_edge)
        self.object_size = object_size
        self.intrinsics = intrinsics
        self.max_depth = float(max_depth)
        self.min_split_fraction = float(min_split_fraction)
        self._kernels: dict[int, np.ndarray] = {}

    # ------------------------------------------------------------------ helpers
    def _kernel(self, height: int, width: int) -> np.ndarray | None:
        if self.morph_kernel == 0:
            return None
        scale = min(height, width) / 128.0
        side = max(self.morph_kernel, round(self.morph_kernel * math.sqrt(scale)) | 1)
        if side not in self._kernels:
            self._kernels[side] = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (side, side))
        return self._kernels[side]

    def _depth_edges(self, depth: np.ndarray) -> np.ndarray:
        """uint8 mask (255) of pixels next to a depth jump larger than ``depth_edge``."""
        d = np.where(np.isfinite(depth), depth, 0.0).astype(np.float32)
        # morphological gradient = local max - local min over a 3x3 cross
        grad = cv2.morphologyEx(d, cv2.MORPH_GRADIENT, cv2.getStructuringElement(
            cv2.MORPH_CROSS, (3, 3)))
        return (grad > self.depth_edge).astype(np.uint8) * 255

    def colour_mask(self, rgb: np.ndarray, colour: str) -> np.ndarray:
        """Cleaned binary mask (uint8 0/255) of one colour; shape (height, width)."""
        rgb = check_rgb(rgb)
        if colour not in self.colours:
            msg = f'Unknown colour {colour!r}; known colours are {sorted(self.colours)}.'
            raise VisionError(msg)
        hsv = cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV)
        return self._clean(self.colours[colour].mask(hsv), *rgb.shape[:2])

    def _clean(self, mask: np.ndarray, height: int, width: int) -> np.ndarray:
        kernel = self._kernel(height, width)
        if kernel is not None:
            mask = cv2.morphologyEx(mask, cv2.MORPH_OPEN, kernel)
            mask = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, kernel)
        return mask

    def _distance_from_size(self, pixel_count: int) -> float:
        if self.object_size is None or self.intrinsics is None or pixel_count <= 0:
            return math.nan
        # projected area ~ (f * size / d)^2 for a compact object of known size
        f = math.sqrt(self.intrinsics.fx * self.intrinsics.fy)
        return f * self.object_size / math.sqrt(pixel_count)

    # ------------------------------------------------------------------ public
    def detect(self, rgb: np.ndarray, depth: np.ndarray | None = None) -> list[Detection]:
        """Detect the coloured objects of one frame.

        Parameters
        ----------
        rgb : ndarray, shape (height, width, 3), dtype uint8
            Colour image (``rgb8``).
        depth : ndarray, shape (height, width), dtype float32 | None
            Depth image registered to ``rgb`` (m, ``32FC1``), or None.

        Returns
        -------
        detections : list of Detection
            One per object, ordered by colour (in the colour table's order), then by size.
        """
        rgb = check_rgb(rgb)
        height, width = rgb.shape[:2]
        if depth is not None:
            depth = check_depth(depth, shape=(height, width))
        min_pixels = max(1, round(self.min_pixels * height * width / (128.0 * 128.0)))
        hsv = cv2.cvtColor(rgb, cv2.COLOR_RGB2HSV)
        kernel = self._kernel(height, width)
        pad = 1 if kernel is None else kernel.shape[0]
        out: list[Detection] = []
        for colour, colour_range in self.colours.items():
            raw = colour_range.mask(hsv)
            # work in the box round this colour's pixels (objects are small in 640x480)
            x, y, w, h = cv2.boundingRect(raw)
            if w == 0 or h == 0:
                continue
            x0, y0 = max(0, x - pad), max(0, y - pad)
            x1, y1 = min(width, x + w + pad), min(height, y + h + pad)
            mask = self._clean(raw[y0:y1, x0:x1], height, width)
            if cv2.countNonZero(mask) < min_pixels:
                continue
            sub_depth = None if depth is None else depth[y0:y1, x0:x1]
            out.extend(self._components(colour, mask, sub_depth, (x0, y0), (height, width),
                                        min_pixels))
        return out

    def _components(self, colour: str, mask: np.ndarray, depth: np.ndarray | None,
                    offset: tuple[int, int], image_size: tuple[int, int], min_pixels: int
                    ) -> list[Detection]:
        """Detections of one colour in a region of interest (``mask``/``depth`` are the region,
        ``offset`` (x, y) its corner in the image, ``image_size`` (height, width))."""
        height, width = image_size
        area = float(height * width)
        n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
        if depth is not None and self.depth_edge > 0 and n > 1:
            edges = self._depth_edges(depth)
            n, labels, stats = self._split_by_depth(mask, labels, stats, n, edges, depth,
                                                    min_pixels)
        dets: list[Detection] = []
        for i in range(1, n):
            count = int(stats[i, cv2.CC_STAT_AREA])
            if count < min_pixels:
                continue
            x, y = int(stats[i, cv2.CC_STAT_LEFT]), int(stats[i, cv2.CC_STAT_TOP])
            w, h = int(stats[i, cv2.CC_STAT_WIDTH]), int(stats[i, cv2.CC_STAT_HEIGHT])
            sub = labels[y:y + h, x:x + w] == i
            distance, source = math.nan, 'none'
            if depth is not None:
                values = depth[y:y + h, x:x + w][sub]
                values = values[np.isfinite(values) & (values > 0) & (values < self.max_depth)]
                if values.size:
                    distance, source = _median(values), 'depth'
            if source == 'none':
                distance = self._distance_from_size(count)
                source = 'none' if math.isnan(distance) else 'size'
            x, y = x + offset[0], y + offset[1]   # image coordinates from here on
            centre = (x + (w - 1) / 2.0, y + (h - 1) / 2.0)
            position = None
            if self.intrinsics is not None and not math.isnan(distance):
                k = self.intrinsics
                position = ((centre[0] - k.cx) * distance / k.fx,
                            (centre[1] - k.cy) * distance / k.fy, distance)
            truncated = x == 0 or y == 0 or x + w >= width or y + h >= height
            dets.append(Detection(colour=colour, bbox=(x, y, w, h), centre=centre,
                                  pixel_count=count, pixel_fraction=count / area,
                                  distance=distance, distance_source=source, position=position,
                                  truncated=truncated, mask=sub))
        dets.sort(key=lambda d: -d.pixel_count)
        return dets

    @classmethod
    def from_parameters(cls, colour_names: Iterable[str],
                        colour_ranges: Mapping[str, Sequence[int]], **kwargs: object
                        ) -> ColourDetector:
        """Build from ROS-style parameters: names plus ``{name: [h_lo, h_hi, s_min, v_min]}``."""
        colours: dict[str, ColourRange] = {}
        for name in colour_names:
            if name in colour_ranges:
                colours[name] = ColourRange.from_sequence(colour_ranges[name])
            elif name in DEFAULT_COLOURS:
                colours[name] = DEFAULT_COLOURS[name]
            else:
                msg = (f'No HSV range for colour {name!r}; add colour_ranges.{name}: '
                       '[hue_low, hue_high, sat_min, val_min] to the parameters.')
                raise VisionError(msg)
        return cls(colours, **kwargs)  # type: ignore[arg-type]

    def _split_by_depth(self, mask: np.ndarray, labels: np.ndarray, stats: np.ndarray, n: int,
                        edges: np.ndarray, depth: np.ndarray, min_pixels: int
                        ) -> tuple[int, np.ndarray, np.ndarray]:
        """Split same-coloured components that contain objects at different depths.

        The component's pixels away from depth jumps ("cores") are labelled; cores whose median
        depths differ by less than ``depth_edge`` belong to one object (faces of one cube), other
        groups become separate objects if each holds at least ``min_split_fraction`` of the
        component; the remaining pixels (jumps, small parts) then go to the nearest object.
        """
        cores = cv2.bitwise_and(mask, cv2.bitwise_not(edges))
        m, core_labels, core_stats, _ = cv2.connectedComponentsWithStats(cores, connectivity=4)
        if m <= 2:
            return n, labels, stats
        min_core = max(2, min_pixels // 2)
        parent_of: dict[int, list[tuple[float, int]]] = {}
        for j in range(1, m):
            if core_stats[j, cv2.CC_STAT_AREA] < min_core:
                continue
            x, y = core_stats[j, cv2.CC_STAT_LEFT], core_stats[j, cv2.CC_STAT_TOP]
            w, h = core_stats[j, cv2.CC_STAT_WIDTH], core_stats[j, cv2.CC_STAT_HEIGHT]
            sub = core_labels[y:y + h, x:x + w] == j
            values = depth[y:y + h, x:x + w][sub]
            values = values[np.isfinite(values) & (values > 0)]
            if values.size == 0:
                continue
            parent = int(labels[y:y + h, x:x + w][sub][0])
            parent_of.setdefault(parent, []).append((_median(values), j))
        new_labels = labels.copy()
        next_label = n
        split_any = False
        for parent, cores_here in parent_of.items():
            cores_here.sort()
            groups: list[list[int]] = [[cores_here[0][1]]]
            for (d_prev, _), (d, j) in itertools.pairwise(cores_here):
                if d - d_prev < self.depth_edge:
                    groups[-1].append(j)
                else:
                    groups.append([j])
            # a part smaller than min_split_fraction of the component is a face of the same
            # object seen at a grazing angle (its depth changes fast), not a second object:
            # leave it unseeded so that it joins its neighbour
            area = max(min_pixels, self.min_split_fraction * stats[parent, cv2.CC_STAT_AREA])
            groups = [g for g in groups if core_stats[g, cv2.CC_STAT_AREA].sum() >= area]
            if len(groups) < 2:
                continue
            split_any = True
            # work inside the component's box: cheap at 640x480 too
            x, y = stats[parent, cv2.CC_STAT_LEFT], stats[parent, cv2.CC_STAT_TOP]
            w, h = stats[parent, cv2.CC_STAT_WIDTH], stats[parent, cv2.CC_STAT_HEIGHT]
            box = (slice(y, y + h), slice(x, x + w))
            inside = labels[box] == parent
            grown = np.zeros((h, w), dtype=np.int32)
            for g, members in enumerate(groups):
                target = parent if g == 0 else next_label
                next_label += 1 if g else 0
                grown[np.isin(core_labels[box], members) & inside] = target
            # hand the remaining pixels (depth-jump pixels, tiny cores) to the nearest object
            kernel = np.ones((3, 3), np.uint8)
            for _ in range(max(h, w)):
                missing = inside & (grown == 0)
                if not missing.any():
                    break
                dilated = cv2.dilate(grown.astype(np.float32), kernel).astype(np.int32)
                grown = np.where(missing, dilated, grown)
            region = new_labels[box]
            region[inside] = grown[inside]
        if not split_any:
            return n, labels, stats
        return next_label, new_labels, _stats(new_labels, next_label)


def _median(values: np.ndarray) -> float:
    """np.median of a non-empty 1-D float array without NaN, to the last bit (same partition,
    middle pair added and halved in the array's dtype), without its ~13 us of wrapper: the
    detector takes one per object and frame."""
    k = values.size // 2
    if values.size % 2:
        return float(np.partition(values, k)[k])
    part = np.partition(values, (k - 1, k))
    return float((part[k - 1] + part[k]) / 2)


def _stats(labels: np.ndarray, n: int) -> np.ndarray:
    """connectedComponentsWithStats-like stats (left, top, width, height, area) of a label image."""
    stats = np.zeros((n, 5), dtype=np.int64)
    ys, xs = np.nonzero(labels)
    lab = labels[ys, xs]
    if lab.size == 0:
        return stats
    stats[:, cv2.CC_STAT_AREA] = np.bincount(lab, minlength=n)[:n]
    present = stats[:, cv2.CC_STAT_AREA] > 0
    big = np.iinfo(np.int64).max
    x0 = np.full(n, big)
    y0 = np.full(n, big)
    x1 = np.full(n, -1)
    y1 = np.full(n, -1)
    np.minimum.at(x0, lab, xs)
    np.minimum.at(y0, lab, ys)
    np.maximum.at(x1, lab, xs)
    np.maximum.at(y1, lab, ys)
    stats[present, cv2.CC_STAT_LEFT] = x0[present]
    stats[present, cv2.CC_STAT_TOP] = y0[present]
    stats[present, cv2.CC_STAT_WIDTH] = x1[present] - x0[present] + 1
    stats[present, cv2.CC_STAT_HEIGHT] = y1[present] - y0[present] + 1
    return stats
