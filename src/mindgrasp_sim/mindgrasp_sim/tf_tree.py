"""The transforms robot_state_publisher computes from a URDF and joint positions (ROS-free).

Each URDF joint gives one transform from its parent link to its child link: the joint origin
(``xyz`` m, ``rpy`` rad, fixed-axis roll-pitch-yaw as URDF defines it) followed by the joint's
motion (a rotation of ``q`` rad about ``axis`` for revolute/continuous joints, a translation of
``q`` m along it for prismatic ones). Fixed joints go to ``/tf_static`` once; moving joints to
``/tf`` at the joint-state rate, as robot_state_publisher does, so a real arm driver with
robot_state_publisher produces the same tree from the same URDF.

    tree = TfTree(Path('mindgrasp_arm.urdf').read_text())
    static = tree.static_transforms()                 # [Transform('palm', 'tcp', ...), ...]
    moving = tree.transforms(dict(zip(robot.arm_joints, q)))  # joints without one: left out
    pos, quat = tree.pose('base_link', 'tcp', {...})  # composed along the chain
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_sim.errors import SimError

__all__ = ['TfTree', 'Transform', 'UrdfJoint']

_MOVING = ('revolute', 'continuous', 'prismatic')


@dataclass(frozen=True)
class UrdfJoint:
    """One URDF joint: origin ``xyz`` (3,) m, ``rpy`` (3,) rad, unit ``axis`` (3,)."""

    name: str
    type: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]


@dataclass(frozen=True)
class Transform:
    """Pose of ``child`` in ``parent``: ``translation`` (3,) m, ``rotation`` (4,) quat xyzw."""

    parent: str
    child: str
    translation: np.ndarray
    rotation: np.ndarray


def _floats(text: str | None, default: tuple[float, float, float], what: str
            ) -> tuple[float, float, float]:
    if text is None:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 3:
        msg = f'URDF {what} must be three numbers, got {text!r}; fix the robot description.'
        raise SimError(msg)
    return values  # type: ignore[return-value]


class TfTree:
    """URDF joints as a tree of transforms (see the module docstring)."""

    def __init__(self, urdf: str) -> None:
        try:
            root = ET.fromstring(urdf)
        except ET.ParseError as exc:
            msg = f'The robot description is not valid XML ({exc}); give a URDF file.'
            raise SimError(msg) from exc
        if root.tag != 'robot':
            msg = f"The robot description's root element is <{root.tag}>, not <robot>."
            raise SimError(msg)
        self.links = [link.get('name', '') for link in root.findall('link')]
        self.joints: list[UrdfJoint] = []
        for j in root.findall('joint'):
            origin = j.find('origin')
            axis = j.find('axis')
            a = np.array(_floats(None if axis is None else axis.get('xyz'), (1.0, 0.0, 0.0),
                                 f"axis of joint {j.get('name')!r}"))
            norm = float(np.linalg.norm(a))
            self.joints.append(UrdfJoint(
                name=j.get('name', ''), type=j.get('type', ''),
                parent=j.find('parent').get('link', ''), child=j.find('child').get('link', ''),
                xyz=_floats(None if origin is None else origin.get('xyz'), (0.0, 0.0, 0.0),
                            f"origin xyz of joint {j.get('name')!r}"),
                rpy=_floats(None if origin is None else origin.get('rpy'), (0.0, 0.0, 0.0),
                            f"origin rpy of joint {j.get('name')!r}"),
                axis=tuple(a / norm) if norm > 0 else (1.0, 0.0, 0.0)))  # type: ignore[arg-type]
        self._by_child = {j.child: j for j in self.joints}
        # URDF rpy: rotations about the fixed axes x, then y, then z
        self._origin_quat = {j.name: tuple(float(v) for v in
                                           Rotation.from_euler('xyz', j.rpy).as_quat())
                             for j in self.joints}
        children = set(self._by_child)
        roots = [link for link in self.links if link not in children]
        if len(roots) != 1:
            msg = f'A URDF tree has one root link; this one has {roots}.'
            raise SimError(msg)
        self.root = roots[0]

    @property
    def moving_joints(self) -> list[str]:
        """Names of the joints that move (revolute, continuous, prismatic), in URDF order."""
        return [j.name for j in self.joints if j.type in _MOVING]

    def _joint_transform(self, joint: UrdfJoint, q: float) -> Transform:
        # plain-float quaternion algebra: this runs for every moving joint at the joint-state rate
        ox, oy, oz, ow = self._origin_quat[joint.name]
        translation = np.array(joint.xyz, dtype=float)
        ax, ay, az = joint.axis
        if joint.type in ('revolute', 'continuous'):
            s, c = math.sin(q / 2.0), math.cos(q / 2.0)
            bx, by, bz, bw = ax * s, ay * s, az * s, c
            rotation = np.array([ow * bx + ox * bw + oy * bz - oz * by,
                                 ow * by - ox * bz + oy * bw + oz * bx,
                                 ow * bz + ox * by - oy * bx + oz * bw,
                                 ow * bw - ox * bx - oy * by - oz * bz])
            return Transform(joint.parent, joint.child, translation, rotation)
        if joint.type == 'prismatic':
            translation = translation + Rotation.from_quat(
                self._origin_quat[joint.name]).apply(np.array(joint.axis) * q)
        return Transform(joint.parent, joint.child, translation,
                         np.array(self._origin_quat[joint.name]))

    def static_transforms(self) -> list[Transform]:
        """Transforms of the fixed joints (for ``/tf_static``)."""
        return [self._joint_transform(j, 0.0) for j in self.joints if j.type not in _MOVING]

    def transforms(self, positions: Mapping[str, float]) -> list[Transform]:
        """Transforms of the moving joints with a position in ``positions`` (rad or m)."""
        return [self._joint_transform(j, float(positions[j.name])) for j in self.joints
                if j.type in _MOVING and j.name in positions]

    def pose(self, parent: str, child: str, positions: Mapping[str, float]
             ) -> tuple[np.ndarray, np.ndarray]:
        """Pose of link ``child`` in its ancestor ``parent``: position (3,) m, quaternion xyzw."""
        translation, rot = np.zeros(3), Rotation.identity()
        link = child
        while link != parent:
            joint = self._by_child.get(link)
            if joint is None:
                msg = f'{parent!r} is not an ancestor of {child!r} in the robot description.'
                raise SimError(msg)
            t = self._joint_transform(joint, float(positions.get(joint.name, 0.0)))
            step = Rotation.from_quat(t.rotation)
            translation = t.translation + step.apply(translation)
            rot = step * rot
            link = joint.parent
        return translation, rot.as_quat()
