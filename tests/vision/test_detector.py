"""ColourDetector on rendered simulator images and on bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_vision import CameraModel, ColourDetector, ColourRange, VisionError

COLOURS = ('red', 'yellow', 'blue')
SHAPES = ('cube', 'cylinder', 'sphere')
TARGET = (0.45, 0.0, 0.025)


@pytest.mark.parametrize('shape', SHAPES)
@pytest.mark.parametrize('colour', COLOURS)
def test_each_colour_and_shape(view, placer, detector, colour, shape):
    rgb, depth = view([{'shape': shape, 'colour': colour, 'position': [0.45, 0.0]}], TARGET,
                      distance=0.3, elevation_deg=50)
    dets = detector.detect(rgb, depth)
    assert [d.colour for d in dets] == [colour]
    det = dets[0]
    u, v, z = placer.project(TARGET)
    x, y, w, h = det.bbox
    assert x <= u <= x + w and y <= v <= y + h
    assert abs(det.centre[0] - u) < 4 and abs(det.centre[1] - v) < 4
    # median depth of the visible surface: in front of the centre by at most the object radius
    assert det.distance_source == 'depth'
    assert z - 0.03 < det.distance < z + 0.005
    assert det.pixel_count == det.mask.sum() > 100
    assert det.pixel_fraction == pytest.approx(det.pixel_count / 128 ** 2)
    assert det.position is not None and det.position[2] == pytest.approx(det.distance)
    assert not det.truncated


def test_home_view_of_set_locations(sim, detector):
    sim.load_scene('set_locations')
    rgb, depth = sim.render_camera()
    dets = detector.detect(rgb, depth)
    # the home pose looks forward: red cube at 0 deg, blue cylinder +40 deg (left), yellow
    # sphere -40 deg (right)
    by_x = sorted(dets, key=lambda d: d.centre[0])
    assert [d.colour for d in by_x] == ['blue', 'red', 'yellow']
    for d in dets:
        assert 0.4 < d.distance < 0.8


def test_two_same_coloured_objects_apart(view, detector):
    objects = [{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.07]},
               {'shape': 'sphere', 'colour': 'red', 'position': [0.45, -0.07]}]
    rgb, depth = view(objects, TARGET, distance=0.35, elevation_deg=50)
    dets = detector.detect(rgb, depth)
    assert [d.colour for d in dets] == ['red', 'red']
    left, right = sorted(dets, key=lambda d: d.centre[0])
    assert left.bbox[0] + left.bbox[2] <= right.bbox[0]
    # the same image without depth: components still separate them
    assert len(detector.detect(rgb)) == 2


def test_same_coloured_objects_overlapping_in_the_image_are_split_by_depth(view, detector):
    # a blue cube in front of a blue cylinder, seen low from the base: their images touch
    objects = [{'shape': 'cube', 'colour': 'blue', 'position': [0.40, 0.0]},
               {'shape': 'cylinder', 'colour': 'blue', 'position': [0.52, 0.03], 'size': 0.06}]
    rgb, depth = view(objects, (0.46, 0.0, 0.03), distance=0.35, elevation_deg=25)
    no_depth = detector.detect(rgb)
    assert len(no_depth) == 1, 'test geometry: the two objects should touch in the image'
    dets = detector.detect(rgb, depth)
    assert len(dets) == 2
    near, far = sorted(dets, key=lambda d: d.distance)
    assert far.distance - near.distance > 0.08
    assert near.pixel_count + far.pixel_count == pytest.approx(no_depth[0].pixel_count, rel=0.02)


def test_occlusion_by_another_colour(view, detector):
    behind = {'shape': 'cylinder', 'colour': 'yellow', 'position': [0.52, 0.0]}
    front = {'shape': 'cube', 'colour': 'red', 'position': [0.42, 0.0]}
    target = (0.47, 0.0, 0.025)
    rgb, depth = view([behind], target, distance=0.35, elevation_deg=20, azimuth_deg=180)
    alone = detector.detect(rgb, depth)
    rgb, depth = view([behind, front], target, distance=0.35, elevation_deg=20, azimuth_deg=180)
    dets = {d.colour: d for d in detector.detect(rgb, depth)}
    assert set(dets) == {'red', 'yellow'}
    assert dets['yellow'].pixel_count < 0.8 * alone[0].pixel_count   # partly hidden
    assert dets['red'].distance < dets['yellow'].distance


def test_distance_from_pixel_size_without_depth(view, detector):
    sizes = ColourDetector(intrinsics=detector.intrinsics, object_size=0.05)
    rgb, depth = view([{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.0]}], TARGET,
                      distance=0.3, elevation_deg=50)
    with_depth = sizes.detect(rgb, depth)[0]
    without = sizes.detect(rgb)[0]
    assert without.distance_source == 'size'
    assert without.distance == pytest.approx(with_depth.distance, rel=0.3)
    assert math.isnan(ColourDetector().detect(rgb)[0].distance)


def test_nothing_to_see(detector):
    grey = np.full((128, 128, 3), 150, np.uint8)
    assert detector.detect(grey, np.ones((128, 128), np.float32)) == []


def test_synthetic_touching_squares_and_bgr_free_thresholds():
    rgb = np.full((64, 96, 3), 200, np.uint8)
    rgb[10:30, 10:30] = (230, 20, 20)    # red
    rgb[10:30, 50:70] = (20, 20, 230)    # blue
    rgb[40:60, 40:50] = (240, 230, 20)   # yellow
    dets = ColourDetector().detect(rgb)
    assert sorted(d.colour for d in dets) == ['blue', 'red', 'yellow']
    red = next(d for d in dets if d.colour == 'red')
    assert red.bbox == (10, 10, 20, 20) and red.centre == (19.5, 19.5)
    # a detector that only knows red
    only_red = ColourDetector({'red': ColourRange(170, 8)})
    assert [d.colour for d in only_red.detect(rgb)] == ['red']


@pytest.mark.parametrize(('rgb', 'depth', 'match'), [
    (np.zeros((32, 32, 4), np.uint8), None, r"shape \(32, 32, 4\).*rgb8"),
    (np.zeros((32, 32, 3), np.float32), None, r"dtype float32, expected uint8"),
    (np.zeros((32, 32, 3), np.uint8), np.zeros((16, 16), np.float32),
     r'16x16 px but the colour image is 32x32 px'),
    (np.zeros((32, 32, 3), np.uint8), np.zeros((32, 32), np.uint16), r"16UC1.*depth / 1000"),
    (np.zeros((32, 32, 3), np.uint8), np.zeros((32, 32, 2), np.float32), r"32FC1"),
    ([[0]], None, r'numpy array'),
])
def test_bad_images(rgb, depth, match):
    with pytest.raises(VisionError, match=match):
        ColourDetector().detect(rgb, depth)


def test_bad_parameters():
    with pytest.raises(VisionError, match=r"'hue_low' is 200.*0\.\.179"):
        ColourRange(200, 10)
    with pytest.raises(VisionError, match=r"'morph_kernel' must be 0 or an odd"):
        ColourDetector(morph_kernel=4)
    with pytest.raises(VisionError, match=r'No HSV range for colour .purple.'):
        ColourDetector.from_parameters(['purple'], {})
    with pytest.raises(VisionError, match=r'needs 4 numbers'):
        ColourRange.from_sequence([1, 2])
    with pytest.raises(ValueError, match=r'not a valid pinhole matrix'):
        CameraModel.from_k(128, 128, [0.0] * 9)


def test_640x480_frame_gives_the_same_objects():
    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation

    with Simulation(scene='set_locations', seed=0,
                    camera=CameraConfig(width=640, height=480)) as big:
        rgb, depth = big.render_camera()
        k, width, height = big.camera_intrinsics()
    dets = ColourDetector(intrinsics=CameraModel.from_k(width, height, k)).detect(rgb, depth)
    assert [d.colour for d in sorted(dets, key=lambda d: d.centre[0])] == ['blue', 'red', 'yellow']
    assert all(d.pixel_count > 500 and 0.4 < d.distance < 0.8 for d in dets)


@pytest.mark.parametrize('dtype', [np.float32, np.float64])
def test_median_is_numpys_to_the_last_bit(dtype) -> None:
    from mindgrasp_vision.detector import _median

    rng = np.random.default_rng(7)
    for _ in range(2000):
        n = int(rng.integers(1, 300))
        values = (rng.random(n) * rng.choice([1e-3, 1.0, 3.0])).astype(dtype)
        if rng.random() < 0.3:     # ties, as quantised depth has
            values = np.round(values, 2).astype(dtype)
        assert _median(values) == float(np.median(values))
