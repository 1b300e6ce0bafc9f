"""Importing vendors' robot descriptions as MIndGrasp arms and hands (ROS-free; run once by a
maintainer, its output committed under ``config/robots/``).

- :func:`split_urdf` cuts a URDF that holds an arm with its hand into an arm URDF and a hand URDF
  at the fixed joint that carries the hand (the mount), keeping the elements in their order, so
  that the description joining them again (:func:`mindgrasp_common.robot_description.merge_urdf`)
  gives PyBullet the same bodies.

Usage (the shipped xArm6 and Panda pairs)::

    python -m mindgrasp_sim.robot_import split \\
        package://pybullet_data/xarm/xarm6_with_gripper.urdf xarm_gripper_base_link \\
        config/robots/urdf/xarm6_arm.urdf config/robots/urdf/xarm_gripper.urdf
"""

from __future__ import annotations

import copy
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from mindgrasp_common.resources import resolve_path

__all__ = ['split_urdf']


def _mesh_uri(name: str, urdf: Path) -> str:
    """A mesh file name of ``urdf`` as a ``package://pybullet_data/...`` URI when the file lives
    in pybullet_data, else an absolute path (PyBullet's rule for ``package://``: beside the
    URDF)."""
    rel = name[len('package://'):] if name.startswith('package://') else name
    path = (urdf.parent / rel).resolve()
    parts = path.parts
    if 'pybullet_data' in parts:
        i = parts.index('pybullet_data')
        return 'package://pybullet_data/' + '/'.join(parts[i + 1:])
    return str(path)


def split_urdf(urdf: str | Path, hand_root: str) -> tuple[str, str, dict]:
    """Cut ``urdf`` at the fixed joint whose child is ``hand_root``.

    Returns the arm URDF text, the hand URDF text (rooted at ``hand_root``) and the mount:
    ``{'joint': name, 'link': flange link, 'xyz': [m], 'rpy': [rad]}``.
    """
    path = resolve_path(str(urdf), 'mindgrasp_sim')
    root = ET.parse(str(path)).getroot()
    for mesh in root.iter('mesh'):
        mesh.set('filename', _mesh_uri(mesh.get('filename', ''), path))
    joints = root.findall('joint')
    children: dict[str, list[str]] = {}
    for j in joints:
        children.setdefault(j.find('parent').get('link'), []).append(j.find('child').get('link'))
    hand_links, todo = set(), [hand_root]
    while todo:
        link = todo.pop()
        hand_links.add(link)
        todo += children.get(link, [])
    mount = next(j for j in joints if j.find('child').get('link') == hand_root)
    origin = mount.find('origin')
    info = {'joint': mount.get('name'), 'link': mount.find('parent').get('link'),
            'xyz': [float(v) for v in (origin.get('xyz', '0 0 0') if origin is not None
                                       else '0 0 0').split()],
            'rpy': [float(v) for v in (origin.get('rpy', '0 0 0') if origin is not None
                                       else '0 0 0').split()]}
    arm = ET.Element('robot', name=root.get('name', 'arm') + '_arm')
    hand = ET.Element('robot', name=hand_root)
    for element in root:
        if element is mount:
            continue
        if element.tag == 'material':
            arm.append(copy.deepcopy(element))
            hand.append(copy.deepcopy(element))
        elif element.tag == 'link':
            (hand if element.get('name') in hand_links else arm).append(element)
        elif element.tag == 'joint':
            (hand if element.find('parent').get('link') in hand_links else arm).append(element)
        elif element.tag in ('transmission', 'gazebo'):
            continue      # ROS control and Gazebo plugins: not read by MIndGrasp
        else:
            arm.append(element)
    texts = []
    for tree in (arm, hand):
        ET.indent(tree)
        texts.append('<?xml version="1.0"?>\n<!-- cut from ' + str(urdf) + ' by '
                     'mindgrasp_sim.robot_import.split_urdf -->\n'
                     + ET.tostring(tree, encoding='unicode') + '\n')
    return texts[0], texts[1], info


def main(argv: list[str] | None = None) -> int:
    """``split URDF HAND_ROOT ARM_OUT HAND_OUT``: print the mount."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) == 5 and args[0] == 'split':
        arm, hand, mount = split_urdf(args[1], args[2])
        Path(args[3]).write_text(arm, encoding='utf-8')
        Path(args[4]).write_text(hand, encoding='utf-8')
        print(mount)
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == '__main__':
    raise SystemExit(main())
