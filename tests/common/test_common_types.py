"""Shared types and constants of mindgrasp_common."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mindgrasp_common import (
    CLASS_NAMES,
    NO_CLASS,
    CameraModel,
    CommonError,
    MiClass,
    Prediction,
    Recording,
    SceneObject,
    class_index,
    class_name,
    objects_from_markers,
    top_down_quat,
    wrap_angle,
)
from mindgrasp_common.robot import (
    ARM_LOWER_LIMITS,
    ARM_UPPER_LIMITS,
    FINGER_CLOSED,
    FINGER_LOWER_LIMIT,
    FINGER_OPEN,
    FINGER_UPPER_LIMIT,
    HOME_POSE,
)


def test_class_names_follow_the_enum():
    assert CLASS_NAMES == ('left_hand', 'right_hand', 'both_hands', 'both_feet')
    assert [CLASS_NAMES[c] for c in MiClass] == [c.name.lower() for c in MiClass]


@pytest.mark.parametrize(('given', 'index'), [
    ('left_hand', 0), ('Right hand', 1), ('both-hands', 2), ('3', 3), (2, 2), (np.int64(1), 1)])
def test_class_index(given, index):
    assert class_index(given) == index


@pytest.mark.parametrize('given', ['elbow', 4, -1, '7', True])
def test_class_index_rejects_unknown(given):
    with pytest.raises(CommonError, match=r"Unknown MI class .*use one of \['left_hand'"):
        class_index(given)


def test_class_name_of_no_class_is_rest():
    assert class_name(NO_CLASS) == 'rest' and class_name(None) == 'rest'
    assert class_name(3) == 'both_feet'


def test_scene_object_label_and_coordinates():
    obj = SceneObject(4, 'red', 'cube', position=[0.5, -0.1, 0.02], size=0.05)
    assert obj.label == 'red cube'
    assert (obj.x, obj.y, obj.z) == (0.5, -0.1, 0.02)
    assert obj.orientation.tolist() == [0.0, 0.0, 0.0, 1.0]
    with pytest.raises(AttributeError):
        obj.colour = 'blue'   # frozen


def test_prediction_defaults_and_name():
    p = Prediction(2, 0.7)
    assert math.isnan(p.stamp) and p.sample_index == -1 and p.distances is None
    assert p.class_name == 'both_hands'


def test_camera_model_from_k_fov_and_backprojection():
    cam = CameraModel.from_fov(128, 96, 60.0)
    assert cam.fx == cam.fy == pytest.approx(48 / math.tan(math.radians(30)))
    again = CameraModel.from_k(128, 96, cam.k.ravel())
    assert again == cam
    point = cam.backproject(cam.cx + cam.fx * 0.1, cam.cy, 2.0)
    assert point == pytest.approx([0.2, 0.0, 2.0])
    half = cam.scaled_to(64, 48)
    assert (half.fx, half.cx) == pytest.approx((cam.fx / 2, cam.cx / 2))


def test_camera_model_rejects_a_bad_matrix():
    with pytest.raises(CommonError, match=r'not a valid pinhole matrix .*check the camera_info'):
        CameraModel.from_k(128, 128, [0.0] * 9)
    with pytest.raises(CommonError, match='not a valid pinhole matrix'):
        CameraModel.from_k(128, 128, [1.0] * 4)


def test_recording_duration_and_empty_events():
    rec = Recording(np.zeros((500, 3)), 250.0, ['C3', 'Cz', 'C4'])
    assert rec.duration == 2.0
    assert rec.events.shape == (0, 2) and rec.annotations == [] and rec.first_sample_index == 0


def test_robot_constants_are_consistent():
    assert len(HOME_POSE) == len(ARM_LOWER_LIMITS) == len(ARM_UPPER_LIMITS) == 6
    assert all(lo < q < hi for lo, q, hi in zip(ARM_LOWER_LIMITS, HOME_POSE, ARM_UPPER_LIMITS,
                                                 strict=True))
    assert FINGER_LOWER_LIMIT < FINGER_OPEN < FINGER_CLOSED < FINGER_UPPER_LIMIT


@pytest.mark.parametrize('angle', [0.0, 3.0, -3.0, 4.0, -7.0, 100.0])
def test_wrap_angle(angle):
    wrapped = wrap_angle(angle)
    assert -math.pi <= wrapped < math.pi
    assert math.isclose(math.cos(wrapped), math.cos(angle), abs_tol=1e-9)
    assert math.isclose(math.sin(wrapped), math.sin(angle), abs_tol=1e-9)


@pytest.mark.parametrize('yaw', [0.0, 0.7, -2.5, 3.1])
def test_top_down_quat_points_down_with_the_thumb_to_the_base(yaw):
    rot = Rotation.from_quat(top_down_quat(yaw)).as_matrix()
    assert rot[:, 2] == pytest.approx([0.0, 0.0, -1.0])
    assert rot[:, 0] == pytest.approx([-math.cos(yaw), -math.sin(yaw), 0.0])


def _marker(id_, type_, text='', ns='objects', rgb=(1.0, 0.0, 0.0), xyz=(0.5, 0.0, 0.025),
            action=0):
    ns_ = SimpleNamespace
    return ns_(id=id_, type=type_, text=text, ns=ns, action=action,
               color=ns_(r=rgb[0], g=rgb[1], b=rgb[2], a=1.0), scale=ns_(x=0.05, y=0.05, z=0.05),
               pose=ns_(position=ns_(x=xyz[0], y=xyz[1], z=xyz[2]),
                        orientation=ns_(x=0.0, y=0.0, z=0.0, w=1.0)))


def test_objects_from_markers():
    markers = [
        _marker(2, 3, 'blue cylinder', rgb=(0, 0, 1), xyz=(1.0, 0.5, 0.03)),
        _marker(0, 1, 'red cube'),
        _marker(1, 2, '', rgb=(0.9, 0.85, 0.1)),          # colour and shape from the marker
        _marker(5, 9, 'a label'),                          # text marker: skipped
        _marker(6, 1, 'red cube', action=2),               # delete: skipped
    ]
    objects = objects_from_markers(markers, origin=(0.5, 0.5))
    assert [(o.object_id, o.label) for o in objects] == [
        (0, 'red cube'), (1, 'yellow sphere'), (2, 'blue cylinder')]
    assert objects[2].position.tolist() == pytest.approx([0.5, 0.0, 0.03])
    assert objects[0].size == 0.05
