"""Robot descriptions: what MIndGrasp needs to know about an arm, in one YAML file beside its URDF.

A description names the arm joints (6 or 7, base to wrist) and their home pose, the gripper (its
joints, open and closed positions, kind and how a grasp is checked), the TCP link, the camera (a
link of the URDF, or an eye-in-hand mount on a link) and, optionally, the velocity limits the
controller may use. Everything else (position, velocity and effort limits) is read from the URDF,
so there is one definition of each value. Angles in rad, velocities in rad/s, efforts in N m,
lengths in m.

Shipped descriptions live in ``config/robots/<name>.yaml`` (config files of ``mindgrasp_sim``);
:func:`load_robot` takes such a name or the path of a lab's own file::

    from mindgrasp_common.robot_description import load_robot
    robot = load_robot('xarm6')            # or load_robot('/path/to/my_arm.yaml')
    robot.arm_joints, robot.home_pose      # ('joint1', ...), (0.0, ...)

The loader checks the description against the URDF before anything moves; each problem is one
:class:`RobotDescriptionError` line naming it and the fix. No ROS, no PyBullet.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.errors import CommonError
from mindgrasp_common.resources import ResourceNotFoundError, resolve_path, resource_path

__all__ = [
    'GRASP_CHECKS',
    'GRIPPER_KINDS',
    'GripperDescription',
    'JointLimits',
    'LinkFrame',
    'RobotDescription',
    'RobotDescriptionError',
    'load_robot',
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
                                              limits, leader)
    return links, joints


def robot_names() -> list[str]:
    """Names of the shipped descriptions (``robot:=NAME``)."""
    return sorted(p.stem for p in resource_path(ROBOTS_PACKAGE, 'robots').glob('*.yaml'))


def robot_choices() -> str:
    """What a ``robot`` option takes, for help texts: the shipped names (:func:`robot_names`)
    or a path, e.g. ``'mindgrasp_arm, panda, xarm6 or a robot description YAML path'``."""
    return f'{", ".join(robot_names())} or a robot description YAML path'


def _find(spec: str | Path) -> Path:
    text = str(spec)
    if text.endswith(('.yaml', '.yml')) or '/' in text:
        # a path, or package://<pkg>/<file> as the URDFs and models are named
        try:
            path = resolve_path(text if '://' in text else Path(text).expanduser(),
                                ROBOTS_PACKAGE)
        except ResourceNotFoundError:
            path = Path(text)
        if not path.is_file():
            msg = (f'The robot description {text!r} does not exist; give a robot YAML file or '
                   f'one of the shipped names {robot_names()}.')
            raise RobotDescriptionError(msg)
        return path
    if text in robot_names():
        return resource_path(ROBOTS_PACKAGE, 'robots', f'{text}.yaml')
    msg = (f'No robot is named {text!r}; use one of {robot_names()} or the path of a robot '
           'YAML file (robot:=path/to/robot.yaml).')
    raise RobotDescriptionError(msg)


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


@functools.lru_cache(maxsize=16)
def _load(path: Path) -> RobotDescription:
    where = f'Robot description {str(path)!r}'
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8'))
    except (OSError, yaml.YAMLError) as exc:
        msg = f'{where} is not readable YAML ({str(exc).splitlines()[0]}); fix the file.'
        raise RobotDescriptionError(msg) from None
    if not isinstance(data, dict):
        msg = f'{where} must be a YAML mapping (name:, urdf:, arm:, gripper:, tcp_link:, camera:).'
        raise RobotDescriptionError(msg)
    uri = _section(data, 'urdf', where, str)
    # a relative URDF path is relative to the description, as URDF mesh paths are to the URDF
    local = path.parent / uri
    try:
        urdf = local if local.is_file() else resolve_path(uri, ROBOTS_PACKAGE)
    except ResourceNotFoundError as exc:
        raise RobotDescriptionError(f'{where}: {exc}') from None
    links, urdf_joints = _read_urdf(urdf, where)

    arm = _section(data, 'arm', where)
    arm_joints = _joints(arm.get('joints'), 'arm joints', where, urdf_joints, urdf)
    if len(arm_joints) not in (6, 7):
        msg = (f'{where}: the arm has {len(arm_joints)} joints {list(arm_joints)}; MIndGrasp '
               'drives arms of 6 or 7 joints, list them base to wrist under arm: joints:.')
        raise RobotDescriptionError(msg)
    n = len(arm_joints)
    arm_limits = tuple(_limits(j, urdf_joints, 'arm', where, urdf) for j in arm_joints)
    home = _numbers(arm.get('home'), n, 'arm: home', where)
    for j, q, lim in zip(arm_joints, home, arm_limits, strict=True):
        if not lim.lower <= q <= lim.upper:
            msg = (f'{where}: the home position {q} rad of {j!r} is outside its URDF limits '
                   f'[{lim.lower}, {lim.upper}]; choose a home pose inside them.')
            raise RobotDescriptionError(msg)
    if arm.get('max_velocity') is None:
        max_velocity = tuple(lim.velocity for lim in arm_limits)
    else:
        max_velocity = _numbers(arm['max_velocity'], n, 'arm: max_velocity', where)
        for j, v, lim in zip(arm_joints, max_velocity, arm_limits, strict=True):
            if not 0.0 < v <= lim.velocity:
                msg = (f'{where}: max_velocity {v} rad/s of {j!r} must be in (0, '
                       f'{lim.velocity}], the URDF velocity limit; lower it.')
                raise RobotDescriptionError(msg)

    g = _section(data, 'gripper', where)
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
    gripper = GripperDescription(kind=kind, joints=g_joints, open=g_open, closed=g_closed,
                                 grasp_check=check, limits=g_limits,
                                 self_collision=self_collision, mimic=mimic)

    tcp = _frame(_section(data, 'tcp', where), 'tcp', where, links, urdf)
    camera = _frame(_section(data, 'camera', where), 'camera', where, links, urdf)
    return RobotDescription(name=str(data.get('name', path.stem)), path=path, urdf_uri=uri,
                            urdf=urdf, arm_joints=arm_joints, home_pose=home,
                            arm_limits=arm_limits, max_velocity=max_velocity, gripper=gripper,
                            tcp=tcp, camera=camera, licence=str(data.get('licence', '')))


def load_robot(spec: str | Path | RobotDescription = 'mindgrasp_arm') -> RobotDescription:
    """The robot description ``spec``: a shipped name (:func:`robot_names`), the path of a robot
    YAML file, or a description (returned as is). Raises :class:`RobotDescriptionError` with one
    line naming the problem and the fix."""
    if isinstance(spec, RobotDescription):
        return spec
    return _load(_find(spec).resolve())
