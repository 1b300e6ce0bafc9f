"""Angles and frames (rotations through :class:`scipy.spatial.transform.Rotation`)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ['top_down_quat', 'wrap_angle']


def wrap_angle(angle: float) -> float:
    """``angle`` (rad) wrapped to [-pi, pi)."""
    return float((angle + math.pi) % (2.0 * math.pi) - math.pi)


def top_down_quat(yaw: float = 0.0) -> np.ndarray:
    """Quaternion (4,) xyzw of a gripper pointing straight down (its z axis along world -z) whose
    x axis points along ``yaw`` + pi (rad, world frame): with ``yaw`` the object's bearing from the
    base, the thumb (gripper +x) faces the base."""
    from scipy.spatial.transform import Rotation  # here: `import mindgrasp_common` stays light

    x = -np.array([math.cos(yaw), math.sin(yaw), 0.0])
    z = np.array([0.0, 0.0, -1.0])
    # columns: the gripper's axes in the world frame
    return Rotation.from_matrix(np.column_stack([x, np.cross(z, x), z])).as_quat()
