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
import math
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.resources import ResourceNotFoundError, resolve_path, resource_path
from mindgrasp_common.robot_types import (
    ArmDescription,
    GripperDescription,
    HandDescription,
    JointLimits,
    LinkFrame,
    RobotDescription,
    RobotDescriptionError,
)
from mindgrasp_common.urdf import ROBOTS_PACKAGE, UrdfJoint, merge_urdf, read_urdf, write_joined

# the types (mindgrasp_common.robot_types) and merge_urdf are part of this module's interface
__all__ = [
    'GRASP_CHECKS',
    'GRIPPER_KINDS',
    'ArmDescription',
    'GripperDescription',
    'HandDescription',
    'JointLimits',
    'LinkFrame',
    'RobotDescription',
    'RobotDescriptionError',
    'arm_names',
    'hand_names',
    'load_arm',
    'load_hand',
    'load_robot',
    'merge_urdf',
    'robot_choices',
    'robot_names',
]

GRIPPER_KINDS = ('parallel_jaw', 'multi_finger')
#: how a closed gripper is judged to hold an object: finger effort, finger contacts, jaw width
GRASP_CHECKS = ('effort', 'contacts', 'width')
_MOVING = ('revolute', 'prismatic', 'continuous')


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


def _joints(names: Any, what: str, where: str, urdf_joints: dict[str, UrdfJoint],
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


def _limits(joint: str, urdf_joints: dict[str, UrdfJoint], what: str, where: str,
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


def _arm_part(arm: dict, where: str, urdf_joints: dict[str, UrdfJoint], urdf: Path
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


def _gripper_part(g: dict, where: str, urdf_joints: dict[str, UrdfJoint], urdf: Path
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


def _root_of(links: set[str], urdf_joints: dict[str, UrdfJoint]) -> str:
    """The root link of a URDF (the link no joint has as its child)."""
    children = {j.child for j in urdf_joints.values()}
    roots = sorted(links - children)
    return roots[0] if roots else ''


def _hand_root_in(gripper: GripperDescription, urdf_joints: dict[str, UrdfJoint]) -> str:
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
    links, urdf_joints = read_urdf(urdf, where)
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
    links, urdf_joints = read_urdf(urdf, where)
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
    arm_links, _ = read_urdf(arm.urdf, where)
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
    urdf = write_joined(text, name)
    where_hand = f'{where} (hand {hand.name!r})'
    hand_links, _ = read_urdf(hand.urdf, where_hand)
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
    links, urdf_joints = read_urdf(urdf, where)
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
