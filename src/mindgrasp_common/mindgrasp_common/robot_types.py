"""The types of a robot description (:mod:`mindgrasp_common.robot_description` loads them from
YAML and URDF files): joint limits, the gripper, frames on links, the arm, the hand and the
joined robot, and the error that names a description's problem. Angles in rad, lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mindgrasp_common.errors import CommonError

__all__ = ['ArmDescription', 'GripperDescription', 'HandDescription', 'JointLimits', 'LinkFrame',
           'RobotDescription', 'RobotDescriptionError']


class RobotDescriptionError(CommonError):
    """A robot description that does not fit its URDF or MIndGrasp (the message says the fix)."""


@dataclass(frozen=True)
class JointLimits:
    """URDF limits of one joint: position ``lower``/``upper`` (rad or m), ``velocity`` (rad/s or
    m/s), ``effort`` (N m or N)."""

    lower: float
    upper: float
    velocity: float
    effort: float


@dataclass(frozen=True)
class GripperDescription:
    """The gripper: ``joints`` driven together from ``open`` (closure 0) to ``closed`` (closure 1),
    one position per joint (rad or m); ``kind`` in :data:`GRIPPER_KINDS`; ``grasp_check`` in
    :data:`GRASP_CHECKS`; ``limits`` (one per joint) from the URDF; ``self_collision``: whether
    the gripper's links (and the links they hang from) collide with each other (false for a
    linkage whose links overlap, as an SRDF's ``disable_collisions`` says); ``mimic``: the
    gripper joints the URDF declares as ``<mimic>`` of another gripper joint, as
    ``(joint, leader, multiplier, offset)`` (position = multiplier * leader + offset, rad or m):
    a simulator couples them to their leader rather than driving them on their own."""

    kind: str
    joints: tuple[str, ...]
    open: tuple[float, ...]
    closed: tuple[float, ...]
    grasp_check: str
    limits: tuple[JointLimits, ...]
    self_collision: bool = True
    mimic: tuple[tuple[str, str, float, float], ...] = ()


@dataclass(frozen=True)
class LinkFrame:
    """A frame fixed to a URDF ``link``: offset ``xyz`` (3,) m and ``rpy`` (3,) rad in it (zeros:
    the link's own frame). The TCP, and the eye-in-hand camera's optical frame (ROS optical
    convention: z forward, x right, y down), mounted on a link as labs add a wrist camera."""

    link: str
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class ArmDescription:
    """An arm without its hand (``config/robots/arms/<name>.yaml``): ``joints`` (n,) base to
    wrist, ``home`` (n,) rad, ``limits`` (n,) from the URDF, ``max_velocity`` (n,) rad/s, and
    ``flange``: the link a hand is mounted on, with the default mount offset in it."""

    name: str
    path: Path
    urdf: Path
    joints: tuple[str, ...]
    home: tuple[float, ...]
    limits: tuple[JointLimits, ...]
    max_velocity: tuple[float, ...]
    flange: LinkFrame
    licence: str = ''


@dataclass(frozen=True)
class HandDescription:
    """A hand (``config/robots/hands/<name>.yaml``): its gripper (joints, closure synergy, kind,
    grasp check), ``root`` (the link it is mounted by), the ``tcp`` and the ``camera``;
    ``grasp``: how the controller holds each shape with this hand, as (parameter, value) pairs of
    the controller's per-shape parameters (``sphere_grasp_height_fraction``, ...)."""

    name: str
    path: Path
    urdf: Path
    root: str
    gripper: GripperDescription
    tcp: LinkFrame
    camera: LinkFrame
    licence: str = ''
    grasp: tuple[tuple[str, float], ...] = ()


@dataclass(frozen=True)
class RobotDescription:
    """One robot as MIndGrasp uses it (see the module docstring).

    ``arm_joints`` (n,) base to wrist, n in {6, 7}; ``home_pose`` (n,) rad; ``arm_limits`` (n,)
    from the URDF; ``max_velocity`` (n,) rad/s the controller may command (the description's, or
    the URDF's); ``urdf`` the resolved URDF path and ``urdf_uri`` as written in the description.
    """

    name: str
    path: Path
    urdf_uri: str
    urdf: Path
    arm_joints: tuple[str, ...]
    home_pose: tuple[float, ...]
    arm_limits: tuple[JointLimits, ...]
    max_velocity: tuple[float, ...]
    gripper: GripperDescription
    tcp: LinkFrame
    camera: LinkFrame
    licence: str = ''
    #: the link the hand hangs from the arm by (its links, and this one, are the hand's)
    hand_root: str = ''
    #: the arm and hand descriptions it was joined from (None: a single-URDF description)
    arm: ArmDescription | None = None
    hand: HandDescription | None = None
    #: the hand's root on the arm's flange link (``link``), offset ``xyz`` m, ``rpy`` rad
    mount: LinkFrame | None = None
    #: what loads it again: the YAML path, or ``'ARM+HAND'``
    spec: str = ''
    #: the controller's per-shape grasp parameters for this hand (HandDescription.grasp, and the
    #: robot YAML's own ``grasp:`` over them)
    grasp: tuple[tuple[str, float], ...] = ()

    @property
    def tcp_link(self) -> str:
        """The link the TCP is fixed to."""
        return self.tcp.link

    @property
    def lower(self) -> tuple[float, ...]:
        """Lower position limits of the arm joints (n,) rad."""
        return tuple(lim.lower for lim in self.arm_limits)

    @property
    def upper(self) -> tuple[float, ...]:
        """Upper position limits of the arm joints (n,) rad."""
        return tuple(lim.upper for lim in self.arm_limits)

    @property
    def effort(self) -> tuple[float, ...]:
        """Effort limits of the arm joints (n,) N m."""
        return tuple(lim.effort for lim in self.arm_limits)
