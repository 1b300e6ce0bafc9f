"""Shared types, constants and data-file lookup of MIndGrasp (ROS-free, imported by every package).

Modules (each defines its names once; the other packages import them from here):

- :mod:`~mindgrasp_common.types`: :class:`SceneObject`, :class:`Prediction`,
  :class:`CameraModel`, :class:`Recording`.
- :mod:`~mindgrasp_common.mi`: motor-imagery class names and indices (:class:`MiClass`).
- :mod:`~mindgrasp_common.states`: the controller's six states (:class:`State`).
- :mod:`~mindgrasp_common.robot`: arm and finger joints, limits, ``HOME_POSE``, the URDF.
- :mod:`~mindgrasp_common.markers`: ``/sim/objects`` markers -> scene objects.
- :mod:`~mindgrasp_common.geometry`: ``wrap_angle`` and frames (scipy ``Rotation``).
- :mod:`~mindgrasp_common.resources`: package data files (:func:`resource_path`).
"""

from mindgrasp_common.errors import CommonError, ResourceNotFoundError
from mindgrasp_common.geometry import top_down_quat, wrap_angle
from mindgrasp_common.markers import objects_from_markers
from mindgrasp_common.mi import (
    CLASS_NAMES,
    DECODER_CLASS_NAMES,
    NO_CLASS,
    REST,
    MiClass,
    class_index,
    class_name,
    decoder_class_index,
)
from mindgrasp_common.resources import resolve_path, resource_path
from mindgrasp_common.states import STATE_NAMES, State
from mindgrasp_common.types import CameraModel, Prediction, Recording, SceneObject

__all__ = [
    'CLASS_NAMES', 'DECODER_CLASS_NAMES', 'NO_CLASS', 'REST', 'STATE_NAMES', 'CameraModel',
    'CommonError', 'MiClass', 'Prediction', 'Recording', 'ResourceNotFoundError', 'SceneObject',
    'State', 'class_index', 'class_name', 'decoder_class_index', 'objects_from_markers',
    'resolve_path', 'resource_path', 'top_down_quat', 'wrap_angle',
]
