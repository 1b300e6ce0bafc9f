"""Robot descriptions: what MIndGrasp needs to know about an arm and its hand, in YAML files
beside their URDFs.

A robot is an **arm** and a **hand** joined by a **mount** (``config/robots/<name>.yaml``)::

    name: xarm6
    arm: xarm6                  # config/robots/arms/xarm6.yaml, or a path
    hand: xarm_gripper          # config/robots/hands/xarm_gripper.yaml, or a path
    mount: {joint: gripper_fix, xyz: [0, 0, 0], rpy: [0, 0, 0]}   # hand root on the flange

An arm description (``arms/<name>.yaml``) names its URDF, the arm joints (6 or 7, base to wrist),
their home pose, the velocity limits the controller may use and the flange (the link a hand is
bolted to). A hand description (``hands/<name>.yaml``) names its URDF, the finger joints and how
they close (the closure synergy: closure c in 0..1 puts every finger joint, mimic or not, at
``open + c * (closed - open)``), the kind of hand, how a grasp is checked, the TCP and the
eye-in-hand camera. Any arm takes any hand: the loader joins the two URDFs into one (the hand's
root link fixed to the flange by the mount) and checks the result; ``load_robot('kuka_iiwa+
franka_hand')`` joins a pair with the arm's default mount and home. A description may also name
one URDF that holds arm and hand (``urdf:`` with ``arm:``, ``gripper:``, ``tcp:``, ``camera:``
sections; the single-file format).

Everything else (position, velocity and effort limits) is read from the URDFs, so there is one
definition of each value. Angles in rad, velocities in rad/s, efforts in N m, lengths in m::

    from mindgrasp_common.robot_description import load_robot
    robot = load_robot('xarm6')            # or load_robot('/path/to/my_arm.yaml')
    robot.arm_joints, robot.home_pose      # ('joint1', ...), (0.0, ...)
    robot.urdf                             # the joined URDF (a cached file)

The loader checks the description against the URDFs before anything moves; each problem is one
:class:`RobotDescriptionError` line naming it and the fix. No ROS, no PyBullet.
"""

from __future__ import annotations

import functools
import hashlib
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from mindgrasp_common.errors import CommonError
from mindgrasp_common.resources import ResourceNotFoundError, resolve_path, resource_path

__all__ = [
    'GRASP_CHECKS',
    'GRIPPER_KINDS',
    'ArmDescription',
    'ArmHeading',
    'GripperDescription',
    'HandDescription',
    'JointLimits',
    'LinkFrame',
    'RobotDescription',
    'RobotDescriptionError',
    'arm_names',
    'base_turn_direction',
    'hand_names',
    'load_arm',
    'load_hand',
    'load_robot',
    'merge_urdf',
    'robot_choices',
    'robot_names',
]

#: the package whose ``robots/`` folder holds the shipped descriptions
ROBOTS_PACKAGE = 'mindgrasp_sim'
GRIPPER_KINDS = ('parallel_jaw', 'multi_finger')
#: how a closed gripper is judged to hold an object: finger effort, finger contacts, jaw width
GRASP_CHECKS = ('effort', 'contacts', 'width')
_MOVING = ('revolute', 'prismatic', 'continuous')


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


@dataclass(frozen=True)
class _UrdfJoint:
    type: str
    child: str
    limits: JointLimits | None
    mimic: tuple[str, float, float] | None = None   # leader joint, multiplier, offset
    parent: str = ''
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)   # origin in the parent link (rad)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)  # in the joint's frame (URDF default)


def _read_urdf(path: Path, where: str) -> tuple[set[str], dict[str, _UrdfJoint]]:
    """Links and joints (name -> type, child link, limits) of the URDF at ``path``."""
    try:
        # ElementTree never fetches external entities; expat (>= 2.4.1) caps entity expansion
        root = ET.parse(str(path)).getroot()
    except (OSError, ET.ParseError) as exc:
        msg = f'{where}: cannot read the URDF {str(path)!r} ({exc}); give a valid URDF file.'
        raise RobotDescriptionError(msg) from None
    links = {link.get('name', '') for link in root.findall('link')}
    joints = {}
    for j in root.findall('joint'):
        lim = j.find('limit')
        limits = None
        if lim is not None and j.get('type') != 'continuous':
            try:
                limits = JointLimits(*(float(lim.get(k, 'nan')) for k in
                                       ('lower', 'upper', 'velocity', 'effort')))
            except ValueError:
                limits = None
        child = j.find('child')
        parent = j.find('parent')
        mimic = j.find('mimic')
        leader = None
        if mimic is not None:
            try:
                leader = (mimic.get('joint', ''), float(mimic.get('multiplier', '1')),
                          float(mimic.get('offset', '0')))
            except ValueError:
                leader = None
        joints[j.get('name', '')] = _UrdfJoint(j.get('type', ''),
                                              '' if child is None else child.get('link', ''),
                                              limits, leader,
                                              '' if parent is None else parent.get('link', ''),
                                              _triple(j.find('origin'), 'rpy', '0 0 0'),
                                              _triple(j.find('axis'), 'xyz', '1 0 0'))
    return links, joints


def _triple(element: ET.Element | None, key: str, default: str) -> tuple[float, float, float]:
    """Three numbers of a URDF attribute (the default when absent or unreadable)."""
    text = default if element is None else element.get(key, default)
    try:
        x, y, z = (float(v) for v in text.split())
    except ValueError:
        x, y, z = (float(v) for v in default.split())
    return x, y, z


@dataclass(frozen=True)
class ArmHeading:
    """Where the arm points (rad, counter-clockwise seen from above, 0 along the base's x axis)
    from the angle of one joint, its first: ``direction * (angle - home)``.

    Exact for the turn of a vertical first joint from a home pose that looks straight ahead, as
    every shipped robot's does (``tests/common/test_robot_description.py`` checks the camera).
    A subject that watches the arm reads its heading this way: the Jaco's first joint turns the
    other way round and sits at 2.93 rad at home, so its angle alone is no heading.
    """

    joint: str = ''          # '' = the first joint of /joint_states
    direction: float = 1.0   # base_turn_direction
    home: float = 0.0        # the joint's angle at home (rad)

    @classmethod
    def of_robot(cls, robot: str | Path | RobotDescription) -> ArmHeading:
        """The heading of ``robot`` (a :func:`load_robot` spec)."""
        robot = load_robot(robot)
        return cls(robot.arm_joints[0], base_turn_direction(robot), robot.home_pose[0])

    def __call__(self, angle: float) -> float:
        """Heading (rad) at the joint ``angle`` (rad)."""
        return self.direction * (angle - self.home)


def base_turn_direction(robot: RobotDescription) -> float:
    """+1.0 when a positive angle of the arm's first joint turns the arm counter-clockwise seen
    from above (its axis points up, in the base frame), -1.0 when the axis points down (the
    Jaco's). The axis is taken through the fixed and first-joint origins from the URDF's root."""
    _, joints = _read_urdf(robot.urdf, f'robot {robot.name!r}')
    by_child = {j.child: j for j in joints.values()}
    joint = joints.get(robot.arm_joints[0])
    if joint is None:
        msg = (f'robot {robot.name!r}: the joint {robot.arm_joints[0]!r} is not in '
               f'{robot.urdf}; check the arm joints.')
        raise RobotDescriptionError(msg)
    rotation = Rotation.from_euler('xyz', joint.rpy)     # URDF rpy: fixed axes
    link = joint.parent
    while link in by_child:                              # up to the root (fixed joints)
        above = by_child[link]
        rotation = Rotation.from_euler('xyz', above.rpy) * rotation
        link = above.parent
    return 1.0 if float(rotation.apply(joint.axis)[2]) >= 0.0 else -1.0


def _numbers(value: Any, n: int, what: str, where: str) -> tuple[float, ...]:
    """``value`` as n finite floats (a scalar is repeated n times)."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = [value] * n
    ok = (isinstance(value, list) and len(value) == n
          and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                  for v in value))
    if not ok:
        msg = f'{where}: {what} must be {n} finite numbers, got {value!r}; give one per joint.'
        raise RobotDescriptionError(msg)
    return tuple(float(v) for v in value)


def _section(data: dict, key: str, where: str, kind: type = dict) -> Any:
    if key not in data:
        msg = f'{where}: the key {key!r} is missing; add it (see config/robots/*.yaml).'
        raise RobotDescriptionError(msg)
    if not isinstance(data[key], kind):
        msg = f'{where}: {key!r} must be a {kind.__name__}, got {data[key]!r}.'
        raise RobotDescriptionError(msg)
    return data[key]


def _joints(names: Any, what: str, where: str, urdf_joints: dict[str, _UrdfJoint],
            urdf: Path) -> tuple[str, ...]:
    if not (isinstance(names, list) and names and all(isinstance(n, str) for n in names)):
        msg = f'{where}: {what} must be a list of joint names, got {names!r}.'
        raise RobotDescriptionError(msg)
    for n in names:
        if n not in urdf_joints:
            msg = (f"{where}: the {what} name the joint {n!r}, which the URDF {urdf.name} lacks; "
                   f"use one of its joints ({', '.join(sorted(urdf_joints))}).")
            raise RobotDescriptionError(msg)
        if urdf_joints[n].type not in _MOVING:
            msg = (f'{where}: the {what} name {n!r}, a {urdf_joints[n].type} joint of '
                   f'{urdf.name}; name moving (revolute or prismatic) joints only.')
            raise RobotDescriptionError(msg)
    return tuple(names)


def _link(name: Any, what: str, where: str, links: set[str], urdf: Path) -> str:
    if not isinstance(name, str) or name not in links:
        msg = (f'{where}: the {what} {name!r} is not a link of the URDF {urdf.name}; name one of '
               f"its links ({', '.join(sorted(links))}).")
        raise RobotDescriptionError(msg)
    return name


def _limits(joint: str, urdf_joints: dict[str, _UrdfJoint], what: str, where: str,
            urdf: Path) -> JointLimits:
    lim = urdf_joints[joint].limits
    if lim is None or not all(math.isfinite(v) for v in (lim.lower, lim.upper, lim.velocity,
                                                          lim.effort)) or lim.lower >= lim.upper:
        msg = (f'{where}: the {what} joint {joint!r} has no position, velocity and effort limits '
               f'in {urdf.name}; add <limit lower= upper= velocity= effort=/> to it.')
        raise RobotDescriptionError(msg)
    return lim


def _frame(data: dict, what: str, where: str, links: set[str], urdf: Path) -> LinkFrame:
    return LinkFrame(link=_link(data.get('link'), f'{what} link', where, links, urdf),
                     xyz=_numbers(data.get('xyz', [0.0] * 3), 3, f'{what}: xyz', where),
                     rpy=_numbers(data.get('rpy', [0.0] * 3), 3, f'{what}: rpy', where))


def _names(folder: str) -> list[str]:
    base = resource_path(ROBOTS_PACKAGE, 'robots')
    base = base / folder if folder else base
    return sorted(p.stem for p in base.glob('*.yaml')) if base.is_dir() else []


def robot_names() -> list[str]:
    """Names of the shipped robots, arm + hand pairs (``robot:=NAME``)."""
    return _names('')


def robot_choices() -> str:
    """What a ``robot`` option takes, for help texts: the shipped names (:func:`robot_names`)
    or a path, e.g. ``'mindgrasp_arm, panda, xarm6 or a robot description YAML path'``."""
    return f'{", ".join(robot_names())} or a robot description YAML path'


def arm_names() -> list[str]:
    """Names of the shipped arm descriptions (``config/robots/arms/<name>.yaml``)."""
    return _names('arms')


def hand_names() -> list[str]:
    """Names of the shipped hand descriptions (``config/robots/hands/<name>.yaml``)."""
    return _names('hands')


def _find(spec: str | Path, folder: str = '', base: Path | None = None) -> Path:
    """The YAML file of ``spec``: a path (relative to ``base``, the description naming it, or to
    the working directory), a ``package://`` URI, or a shipped name of ``folder``."""
    text = str(spec)
    what = {'': 'robot', 'arms': 'arm', 'hands': 'hand'}[folder]
    known = _names(folder)
    if text.endswith(('.yaml', '.yml')) or '/' in text:
        path = None
        if base is not None and '://' not in text and (base / text).is_file():
            path = base / text
        else:
            try:
                path = resolve_path(text if '://' in text else Path(text).expanduser(),
                                    ROBOTS_PACKAGE)
            except ResourceNotFoundError:
                path = Path(text)
        if not path.is_file():
            msg = (f'The {what} description {text!r} does not exist; give a {what} YAML file or '
                   f'one of the shipped names {known}.')
            raise RobotDescriptionError(msg)
        return path
    if text in known:
        parts = ('robots', folder, f'{text}.yaml') if folder else ('robots', f'{text}.yaml')
        return resource_path(ROBOTS_PACKAGE, *parts)
    if folder:
        msg = (f'No {what} is named {text!r}; use one of {known} or the path of a {what} YAML '
               f'file.')
    else:
        # (a pair ARM+HAND of arm_names() and hand_names() works too: load_robot)
        msg = (f'No robot is named {text!r}; use one of {known} or the path of a robot YAML '
               'file (robot:=path/to/robot.yaml).')
    raise RobotDescriptionError(msg)


def _read_yaml(path: Path, where: str) -> dict:
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8'))
    except (OSError, yaml.YAMLError) as exc:
        msg = f'{where} is not readable YAML ({str(exc).splitlines()[0]}); fix the file.'
        raise RobotDescriptionError(msg) from None
    if not isinstance(data, dict):
        msg = (f'{where} must be a YAML mapping (a robot: name:, arm:, hand:, mount:; see '
               'config/robots/*.yaml).')
        raise RobotDescriptionError(msg)
    return data


def _urdf_of(data: dict, path: Path, where: str) -> tuple[str, Path]:
    uri = _section(data, 'urdf', where, str)
    # a relative URDF path is relative to the description, as URDF mesh paths are to the URDF
    local = path.parent / uri
    try:
        return uri, (local.resolve() if local.is_file() else resolve_path(uri, ROBOTS_PACKAGE))
    except ResourceNotFoundError as exc:
        raise RobotDescriptionError(f'{where}: {exc}') from None


def _arm_part(arm: dict, where: str, urdf_joints: dict[str, _UrdfJoint], urdf: Path
              ) -> tuple[tuple[str, ...], tuple[JointLimits, ...], tuple[float, ...],
                         tuple[float, ...]]:
    """Joints, limits, home and max_velocity of an ``arm`` section (or arm description)."""
    arm_joints = _joints(arm.get('joints'), 'arm joints', where, urdf_joints, urdf)
    if len(arm_joints) not in (6, 7):
        msg = (f'{where}: the arm has {len(arm_joints)} joints {list(arm_joints)}; MIndGrasp '
               'drives arms of 6 or 7 joints, list them base to wrist under arm: joints:.')
        raise RobotDescriptionError(msg)
    arm_limits = tuple(_limits(j, urdf_joints, 'arm', where, urdf) for j in arm_joints)
    home = _home(arm.get('home'), arm_joints, arm_limits, where)
    max_velocity = _max_velocity(arm.get('max_velocity'), arm_joints, arm_limits, where)
    return arm_joints, arm_limits, home, max_velocity


def _home(value: Any, joints: tuple[str, ...], limits: tuple[JointLimits, ...], where: str
          ) -> tuple[float, ...]:
    home = _numbers(value, len(joints), 'arm: home', where)
    for j, q, lim in zip(joints, home, limits, strict=True):
        if not lim.lower <= q <= lim.upper:
            msg = (f'{where}: the home position {q} rad of {j!r} is outside its URDF limits '
                   f'[{lim.lower}, {lim.upper}]; choose a home pose inside them.')
            raise RobotDescriptionError(msg)
    return home


def _max_velocity(value: Any, joints: tuple[str, ...], limits: tuple[JointLimits, ...],
                  where: str) -> tuple[float, ...]:
    if value is None:
        return tuple(lim.velocity for lim in limits)
    max_velocity = _numbers(value, len(joints), 'arm: max_velocity', where)
    for j, v, lim in zip(joints, max_velocity, limits, strict=True):
        if not 0.0 < v <= lim.velocity:
            msg = (f'{where}: max_velocity {v} rad/s of {j!r} must be in (0, '
                   f'{lim.velocity}], the URDF velocity limit; lower it.')
            raise RobotDescriptionError(msg)
    return max_velocity


def _gripper_part(g: dict, where: str, urdf_joints: dict[str, _UrdfJoint], urdf: Path
                  ) -> GripperDescription:
    g_joints = _joints(g.get('joints'), 'gripper joints', where, urdf_joints, urdf)
    g_limits = tuple(_limits(j, urdf_joints, 'gripper', where, urdf) for j in g_joints)
    g_open = _numbers(g.get('open'), len(g_joints), 'gripper: open', where)
    g_closed = _numbers(g.get('closed'), len(g_joints), 'gripper: closed', where)
    for j, a, b, lim in zip(g_joints, g_open, g_closed, g_limits, strict=True):
        if not (lim.lower <= a <= lim.upper and lim.lower <= b <= lim.upper):
            msg = (f'{where}: the gripper positions open {a} and closed {b} of {j!r} must lie in '
                   f'its URDF limits [{lim.lower}, {lim.upper}]; change open:/closed:.')
            raise RobotDescriptionError(msg)
    kind = g.get('kind')
    if kind not in GRIPPER_KINDS:
        msg = f'{where}: gripper kind {kind!r} is not one of {list(GRIPPER_KINDS)}; pick one.'
        raise RobotDescriptionError(msg)
    check = g.get('grasp_check')
    if check not in GRASP_CHECKS:
        msg = (f'{where}: gripper grasp_check {check!r} is not one of {list(GRASP_CHECKS)}; '
               'pick how a closed gripper is judged to hold an object.')
        raise RobotDescriptionError(msg)
    self_collision = g.get('self_collision', True)
    if not isinstance(self_collision, bool):
        msg = f'{where}: gripper self_collision must be true or false, got {self_collision!r}.'
        raise RobotDescriptionError(msg)
    # URDF mimic joints among the gripper joints (PyBullet does not enforce <mimic>)
    mimic = tuple((j, *urdf_joints[j].mimic) for j in g_joints
                  if urdf_joints[j].mimic is not None and urdf_joints[j].mimic[0] in g_joints)
    return GripperDescription(kind=kind, joints=g_joints, open=g_open, closed=g_closed,
                              grasp_check=check, limits=g_limits,
                              self_collision=self_collision, mimic=mimic)


def _root_of(links: set[str], urdf_joints: dict[str, _UrdfJoint]) -> str:
    """The root link of a URDF (the link no joint has as its child)."""
    children = {j.child for j in urdf_joints.values()}
    roots = sorted(links - children)
    return roots[0] if roots else ''


def _hand_root_in(gripper: GripperDescription, urdf_joints: dict[str, _UrdfJoint]) -> str:
    """The link a single-URDF robot's hand hangs by: the link the first gripper joint turns on,
    followed up through fixed joints (the palm and what is welded to it)."""
    by_child = {j.child: j for j in urdf_joints.values()}
    link = urdf_joints[gripper.joints[0]].parent
    while link in by_child and by_child[link].type == 'fixed':
        link = by_child[link].parent
    return link


@functools.lru_cache(maxsize=32)
def _load_arm(path: Path) -> ArmDescription:
    where = f'Arm description {str(path)!r}'
    data = _read_yaml(path, where)
    _, urdf = _urdf_of(data, path, where)
    links, urdf_joints = _read_urdf(urdf, where)
    joints, limits, home, max_velocity = _arm_part(data, where, urdf_joints, urdf)
    flange = _frame(_section(data, 'flange', where), 'flange', where, links, urdf)
    return ArmDescription(name=str(data.get('name', path.stem)), path=path, urdf=urdf,
                          joints=joints, home=home, limits=limits, max_velocity=max_velocity,
                          flange=flange, licence=str(data.get('licence', '')))


@functools.lru_cache(maxsize=32)
def _load_hand(path: Path) -> HandDescription:
    where = f'Hand description {str(path)!r}'
    data = _read_yaml(path, where)
    _, urdf = _urdf_of(data, path, where)
    links, urdf_joints = _read_urdf(urdf, where)
    gripper = _gripper_part(data, where, urdf_joints, urdf)
    root = _root_of(links, urdf_joints)
    return HandDescription(
        name=str(data.get('name', path.stem)), path=path, urdf=urdf, root=root, gripper=gripper,
        tcp=_frame(_section(data, 'tcp', where), 'tcp', where, links, urdf),
        camera=_frame(_section(data, 'camera', where), 'camera', where, links, urdf),
        licence=str(data.get('licence', '')),
        grasp=tuple(sorted(_grasp_part(data, where).items())))


def _grasp_part(data: dict, where: str) -> dict[str, float]:
    """The ``grasp:`` mapping (controller parameter -> number) of a hand or robot YAML; the
    controller checks the names (:meth:`mindgrasp_fsm.params.FsmParams.apply_robot`)."""
    grasp = data.get('grasp') or {}
    ok = isinstance(grasp, dict) and all(
        isinstance(k, str) and isinstance(v, (int, float)) and not isinstance(v, bool)
        and math.isfinite(v) for k, v in grasp.items())
    if not ok:
        msg = (f"{where}: 'grasp' must map controller parameters to numbers (e.g. "
               f'sphere_grasp_height_fraction: 0.5), got {grasp!r}.')
        raise RobotDescriptionError(msg)
    return {k: float(v) for k, v in grasp.items()}


def load_arm(spec: str | Path) -> ArmDescription:
    """The arm description ``spec``: a shipped name (:func:`arm_names`) or a YAML path."""
    return _load_arm(_find(spec, 'arms').resolve())


def load_hand(spec: str | Path) -> HandDescription:
    """The hand description ``spec``: a shipped name (:func:`hand_names`) or a YAML path."""
    return _load_hand(_find(spec, 'hands').resolve())


# ------------------------------------------------------------------ joining arm and hand URDFs
def _absolute_meshes(root: ET.Element, urdf: Path, where: str) -> None:
    """Rewrite the mesh file names of ``root`` (a URDF read from ``urdf``) as absolute paths, so
    the joined file can live anywhere: ``package://`` URIs through the project's resources (or
    beside the URDF, as PyBullet looks for them), relative paths from the URDF's folder."""
    for mesh in root.iter('mesh'):
        name = mesh.get('filename', '')
        found = None
        if name.startswith('package://'):
            with_package = name[len('package://'):]
            try:
                found = resolve_path(name, ROBOTS_PACKAGE)
            except ResourceNotFoundError:
                found = None
            if found is None or not found.is_file():
                # PyBullet's own rule: drop package:// and look beside the URDF and above it
                for folder in (urdf.parent, *urdf.parent.parents[:2]):
                    if (folder / with_package).is_file():
                        found = folder / with_package
                        break
        elif name.startswith('file://'):
            found = Path(name[len('file://'):])
        elif name:
            found = urdf.parent / name
        if found is None or not found.is_file():
            msg = (f'{where}: the mesh {name!r} of {urdf.name} does not exist; give a path '
                   'relative to the URDF or a package:// URI the project can resolve.')
            raise RobotDescriptionError(msg)
        mesh.set('filename', str(found.resolve()))


def _origin(xyz: tuple[float, ...], rpy: tuple[float, ...]) -> ET.Element:
    return ET.Element('origin', xyz=' '.join(repr(float(v)) for v in xyz),
                      rpy=' '.join(repr(float(v)) for v in rpy))


def _compose(origin: ET.Element | None, xyz: tuple[float, ...], rpy: tuple[float, ...]
             ) -> ET.Element:
    """The origin of a joint followed by the offset (xyz m, rpy rad)."""
    if origin is None:
        return _origin(xyz, rpy)
    if not any(xyz) and not any(rpy):
        return origin
    p0 = np.array([float(v) for v in origin.get('xyz', '0 0 0').split()])
    r0 = Rotation.from_euler('xyz', [float(v) for v in origin.get('rpy', '0 0 0').split()])
    r1 = Rotation.from_euler('xyz', rpy)
    return _origin(tuple(p0 + r0.apply(xyz)), tuple((r0 * r1).as_euler('xyz')))


def merge_urdf(arm: ArmDescription, hand: HandDescription, mount: LinkFrame,
               joint: str = 'hand_mount', name: str = '') -> str:
    """The URDF text of ``arm`` with ``hand`` fixed to it: the hand's root link on the link
    ``mount.link`` (the flange), offset by ``mount.xyz`` m and ``mount.rpy`` rad, through a fixed
    joint named ``joint``. Mesh paths become absolute.

    An empty flange link (no inertial, visual or collision: a frame, as ROS-Industrial's
    ``tool0``) that no joint hangs from is replaced by the hand's root, the mount appended to the
    joint that carried it (its axis expressed in the turned frame): no massless link enters the
    simulation. The arm's elements come first, the mount joint, then the hand's, in their files'
    order (PyBullet numbers links in that order).
    """
    where = f'Joining the arm {arm.name!r} and the hand {hand.name!r}'
    trees = []
    for part in (arm, hand):
        try:
            root = ET.parse(str(part.urdf)).getroot()
        except (OSError, ET.ParseError) as exc:
            msg = f'{where}: cannot read the URDF {str(part.urdf)!r} ({exc}); give a valid URDF.'
            raise RobotDescriptionError(msg) from None
        _absolute_meshes(root, part.urdf, where)
        trees.append(root)
    arm_root, hand_root = trees
    for tag in ('link', 'joint'):
        clash = sorted({e.get('name') for e in arm_root.findall(tag)}
                       & {e.get('name') for e in hand_root.findall(tag)})
        if clash:
            msg = (f'{where}: both URDFs have a {tag} named {clash[0]!r}; rename it in one of '
                   'them (e.g. prefix the hand\'s names).')
            raise RobotDescriptionError(msg)
    flange = next(e for e in arm_root.findall('link') if e.get('name') == mount.link)
    into = [j for j in arm_root.findall('joint')
            if j.find('child') is not None and j.find('child').get('link') == mount.link]
    hangs = [j for j in arm_root.findall('joint')
             if j.find('parent') is not None and j.find('parent').get('link') == mount.link]
    replace = len(flange) == 0 and not hangs and len(into) == 1
    out = ET.Element('robot', name=name or f'{arm.name}+{hand.name}')
    materials: set[str] = set()
    for element in arm_root:
        if element is flange and replace:
            continue
        if element.tag == 'material':
            materials.add(element.get('name', ''))
        if element is (into[0] if replace else None):
            element.find('child').set('link', hand.root)
            origin = element.find('origin')
            new = _compose(origin, mount.xyz, mount.rpy)
            if origin is not None and new is not origin:
                element.remove(origin)
            if new is not origin:
                element.insert(0, new)
            axis = element.find('axis')
            if axis is not None and any(mount.rpy):
                # the joint's axis is in its child's frame, now the hand's root, turned by the
                # mount: the same axis in the new frame (the Jaco's flange is turned by pi)
                a = Rotation.from_euler('xyz', mount.rpy).inv().apply(
                    [float(v) for v in axis.get('xyz', '1 0 0').split()])
                axis.set('xyz', ' '.join(repr(float(v)) for v in np.round(a, 12) + 0.0))
        out.append(element)
    if not replace:
        fixed = ET.SubElement(out, 'joint', name=joint, type='fixed')
        ET.SubElement(fixed, 'parent', link=mount.link)
        ET.SubElement(fixed, 'child', link=hand.root)
        fixed.append(_origin(mount.xyz, mount.rpy))
    for element in hand_root:
        if element.tag == 'material' and element.get('name', '') in materials:
            continue      # a colour both files define: the arm's
        out.append(element)
    ET.indent(out)
    return '<?xml version="1.0"?>\n' + ET.tostring(out, encoding='unicode') + '\n'


def _cache_dir() -> Path:
    base = os.environ.get('XDG_CACHE_HOME') or str(Path.home() / '.cache')
    for folder in (Path(base) / 'mindgrasp' / 'robots',
                   Path(tempfile.gettempdir()) / f'mindgrasp-robots-{os.getuid()}'):
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        if os.access(folder, os.W_OK):
            return folder
    msg = f'Cannot write the joined robot URDF to {base}/mindgrasp/robots nor to the temp folder.'
    raise RobotDescriptionError(msg)


def _write_joined(text: str, name: str) -> Path:
    """Write a joined URDF once, named by its content (processes that join the same pair share
    the file; the write is atomic)."""
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    safe = ''.join(c if c.isalnum() or c in '-_' else '_' for c in name)
    path = _cache_dir() / f'{safe}-{digest}.urdf'
    if not path.is_file():
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix='.tmp')
        with os.fdopen(fd, 'w', encoding='utf-8') as f:
            f.write(text)
        os.replace(tmp, path)
    return path


def _load_pair(data: dict, path: Path | None, where: str) -> RobotDescription:
    base = path.parent if path is not None else None
    arm_spec, hand_spec = data.get('arm'), data.get('hand')
    for key, spec in (('arm', arm_spec), ('hand', hand_spec)):
        if not isinstance(spec, str):
            known = arm_names() if key == 'arm' else hand_names()
            msg = (f'{where}: {key!r} must name a shipped {key} ({known}) or the path of a '
                   f'{key} YAML file, got {spec!r}.')
            raise RobotDescriptionError(msg)
    arm = _load_arm(_find(arm_spec, 'arms', base).resolve())
    hand = _load_hand(_find(hand_spec, 'hands', base).resolve())
    m = data.get('mount', {}) or {}
    if not isinstance(m, dict):
        msg = f"{where}: 'mount' must be a mapping (link:, joint:, xyz:, rpy:), got {m!r}."
        raise RobotDescriptionError(msg)
    arm_links, _ = _read_urdf(arm.urdf, where)
    mount = LinkFrame(
        link=_link(m.get('link', arm.flange.link), 'mount link', where, arm_links, arm.urdf),
        xyz=_numbers(m.get('xyz', list(arm.flange.xyz)), 3, 'mount: xyz', where),
        rpy=_numbers(m.get('rpy', list(arm.flange.rpy)), 3, 'mount: rpy', where))
    joint = m.get('joint', 'hand_mount')
    if not isinstance(joint, str) or not joint:
        msg = f'{where}: mount joint must be a joint name, got {joint!r}.'
        raise RobotDescriptionError(msg)
    name = str(data.get('name', path.stem if path is not None else f'{arm.name}+{hand.name}'))
    text = merge_urdf(arm, hand, mount, joint, name)
    urdf = _write_joined(text, name)
    where_hand = f'{where} (hand {hand.name!r})'
    hand_links, _ = _read_urdf(hand.urdf, where_hand)
    tcp = hand.tcp if 'tcp' not in data else _frame(_section(data, 'tcp', where), 'tcp', where,
                                                    hand_links, hand.urdf)
    camera = hand.camera if 'camera' not in data else _frame(
        _section(data, 'camera', where), 'camera', where, hand_links | arm_links, urdf)
    home = arm.home if data.get('home') is None else _home(data['home'], arm.joints, arm.limits,
                                                           where)
    max_velocity = arm.max_velocity if data.get('max_velocity') is None else _max_velocity(
        data['max_velocity'], arm.joints, arm.limits, where)
    licence = str(data.get('licence', '')) or '; '.join(
        f'{part.name}: {part.licence}' for part in (arm, hand) if part.licence)
    return RobotDescription(
        name=name, path=path if path is not None else hand.path, urdf_uri=str(urdf), urdf=urdf,
        arm_joints=arm.joints, home_pose=home, arm_limits=arm.limits, max_velocity=max_velocity,
        gripper=hand.gripper, tcp=tcp, camera=camera, licence=licence, hand_root=hand.root,
        arm=arm, hand=hand, mount=mount, spec=str(path) if path is not None else name,
        grasp=tuple(sorted({**dict(hand.grasp), **_grasp_part(data, where)}.items())))


def _load_single(data: dict, path: Path, where: str) -> RobotDescription:
    uri, urdf = _urdf_of(data, path, where)
    links, urdf_joints = _read_urdf(urdf, where)
    arm_joints, arm_limits, home, max_velocity = _arm_part(_section(data, 'arm', where), where,
                                                           urdf_joints, urdf)
    gripper = _gripper_part(_section(data, 'gripper', where), where, urdf_joints, urdf)
    tcp = _frame(_section(data, 'tcp', where), 'tcp', where, links, urdf)
    camera = _frame(_section(data, 'camera', where), 'camera', where, links, urdf)
    return RobotDescription(name=str(data.get('name', path.stem)), path=path, urdf_uri=uri,
                            urdf=urdf, arm_joints=arm_joints, home_pose=home,
                            arm_limits=arm_limits, max_velocity=max_velocity, gripper=gripper,
                            tcp=tcp, camera=camera, licence=str(data.get('licence', '')),
                            hand_root=_hand_root_in(gripper, urdf_joints), spec=str(path),
                            grasp=tuple(sorted(_grasp_part(data, where).items())))


@functools.lru_cache(maxsize=16)
def _load(path: Path) -> RobotDescription:
    where = f'Robot description {str(path)!r}'
    data = _read_yaml(path, where)
    if 'urdf' not in data and ('hand' in data or isinstance(data.get('arm'), str)):
        return _load_pair(data, path, where)
    return _load_single(data, path, where)


@functools.lru_cache(maxsize=16)
def _load_named_pair(arm: str, hand: str) -> RobotDescription:
    return _load_pair({'arm': arm, 'hand': hand, 'name': f'{arm}+{hand}'}, None,
                      f'Robot {arm}+{hand}')


def load_robot(spec: str | Path | RobotDescription = 'mindgrasp_arm') -> RobotDescription:
    """The robot description ``spec``: a shipped name (:func:`robot_names`), a pair
    ``'ARM+HAND'`` of shipped arm and hand names (the arm's default mount and home), the path of
    a robot YAML file, or a description (returned as is). Raises :class:`RobotDescriptionError`
    with one line naming the problem and the fix."""
    if isinstance(spec, RobotDescription):
        return spec
    text = str(spec)
    if '+' in text and '/' not in text and not text.endswith(('.yaml', '.yml')):
        arm, _, hand = text.partition('+')
        _find(arm, 'arms')
        _find(hand, 'hands')
        return _load_named_pair(arm, hand)
    return _load(_find(spec).resolve())
