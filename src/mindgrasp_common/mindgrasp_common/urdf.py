"""URDF files of robot descriptions: reading their links and joints, and joining an arm's URDF
and a hand's into one (:func:`merge_urdf`, written once per content by :func:`write_joined`).
ElementTree never fetches external entities; expat (>= 2.4.1) caps entity expansion.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
from mindgrasp_common.robot_types import (
    ArmDescription,
    HandDescription,
    JointLimits,
    LinkFrame,
    RobotDescriptionError,
)

__all__ = ['ROBOTS_PACKAGE', 'UrdfJoint', 'merge_urdf', 'read_urdf', 'write_joined']

#: the package whose ``robots/`` folder holds the shipped descriptions
ROBOTS_PACKAGE = 'mindgrasp_sim'


@dataclass(frozen=True)
class UrdfJoint:
    type: str
    child: str
    limits: JointLimits | None
    mimic: tuple[str, float, float] | None = None   # leader joint, multiplier, offset
    parent: str = ''
    rpy: tuple[float, float, float] = (0.0, 0.0, 0.0)   # origin in the parent link (rad)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)  # in the joint's frame (URDF default)


def read_urdf(path: Path, where: str) -> tuple[set[str], dict[str, UrdfJoint]]:
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
        joints[j.get('name', '')] = UrdfJoint(j.get('type', ''),
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


def write_joined(text: str, name: str) -> Path:
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
