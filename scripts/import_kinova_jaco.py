"""Import Kinova's Jaco 2 (j2n6s300: six joints, three fingers) as a MIndGrasp arm and hand.

Run once by a maintainer; its output is committed (config/robots/urdf/kinova_jaco_arm.urdf,
config/robots/urdf/jaco_three_finger.urdf, config/robots/meshes/kinova_jaco/,
config/robots/meshes/jaco_three_finger/), so neither xacro nor trimesh is a runtime dependency::

    git clone https://github.com/Kinovarobotics/kinova-ros /tmp/kinova-ros
    pip install xacro==2.1.1 trimesh fast-simplification   # import-time tools only
    sed -i 's#$(find kinova_description)#/tmp/kinova-ros/kinova_description#g' \\
        /tmp/kinova-ros/kinova_description/urdf/*.xacro
    xacro /tmp/kinova-ros/kinova_description/urdf/j2n6s300_standalone.xacro > /tmp/j2n6s300.urdf
    python scripts/import_kinova_jaco.py /tmp/j2n6s300.urdf /tmp/kinova-ros config/robots

What it changes in Kinova's expanded URDF, and why:

- the hand (``hand_3finger`` with the ring of joint 6, and the six finger links) moves from
  ``j2n6s300_link_6`` onto its own link ``j2n6s300_link_hand``, link 6 turned by pi about x
  (z out of the hand, as other hands' roots), so the arm ends in an empty flange link (which
  the loader replaces by any hand's root, turned back by the flange's rpy); Kinova's
  ``end_effector`` frame becomes the hand description's TCP;
- joints 1, 4, 5 and 6 are ``continuous``; MIndGrasp's controller needs position limits, so they
  become revolute within the xacro's own limits (+-2 pi);
- PyBullet reads no COLLADA: each mesh (Kinova's STL export of the same geometry) is decimated to
  at most FACES triangles and written as binary STL, used for the visual and the collision shape
  (PyBullet collides with a mesh's convex hull, which the decimation keeps);
- the carbon fibre is coloured black-grey, as the arm is (Kinova's pale blue reads as a blue
  object to the colour detector);
- the finger links weigh 200 g instead of 10 g (see FINGER_MASS);
- the ``world``/``root`` links, ROS-control transmissions and Gazebo plugins are left out.
"""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

FACES = 1500
FINGER_MASS = 0.2    # kg
PREFIX = 'j2n6s300_'
HAND = PREFIX + 'link_hand'
SOURCE = 'Kinovarobotics/kinova-ros kinova_description/urdf/j2n6s300_standalone.xacro'


def _header(licence: str, what: str) -> str:
    return (f'<?xml version="1.0"?>\n<!-- {what}: generated from {SOURCE} (commit 924781d3) by '
            'xacro 2.1.1 and scripts/import_kinova_jaco.py (see its docstring); do not edit.\n'
            'Copyright (c) 2017, Kinova Robotics inc. Licence of the description and meshes '
            '(BSD-3-Clause):\n\n' + licence.replace('--', '- -') + '-->\n')


def _flip(element: ET.Element) -> None:
    """Express the ``<origin>`` of ``element`` (a link's visual, collision or inertial, or a
    joint) in its frame turned by pi about x."""
    origin = element.find('origin')
    if origin is None:
        origin = ET.SubElement(element, 'origin')
        element.remove(origin)
        element.insert(0, origin)
    xyz = np.array([float(v) for v in origin.get('xyz', '0 0 0').split()])
    rpy = [float(v) for v in origin.get('rpy', '0 0 0').split()]
    flip = Rotation.from_euler('x', math.pi)
    rot = flip * Rotation.from_euler('xyz', rpy)
    origin.set('xyz', ' '.join(f'{v:.6g}' for v in np.round(flip.apply(xyz), 9) + 0.0))
    origin.set('rpy', ' '.join(f'{v:.10g}' for v in rot.as_euler('xyz')))


def main(expanded: str, kinova: str, out: str) -> None:
    src, kinova_dir, out_dir = Path(expanded), Path(kinova), Path(out)
    licence = (kinova_dir / 'LICENSE').read_text(encoding='utf-8')
    root = ET.parse(str(src)).getroot()
    for colour in root.iter('color'):
        # Kinova's carbon fibre is black; the URDF's pale blue reads as a blue object to the
        # colour detector when the fingers enter the wrist camera's view
        colour.set('rgba', '0.2 0.2 0.22 1')
    for tag in ('transmission', 'gazebo'):
        for e in root.findall(tag):
            root.remove(e)
    links = {e.get('name'): e for e in root.findall('link')}
    joints = {e.get('name'): e for e in root.findall('joint')}
    for name in ('world', 'root', PREFIX + 'end_effector'):
        root.remove(links.pop(name))
    for name in ('connect_root_and_world', PREFIX + 'joint_base', PREFIX + 'joint_end_effector'):
        root.remove(joints.pop(name))
    for j in joints.values():
        if j.get('type') == 'continuous':
            j.set('type', 'revolute')
            lim = j.find('limit')
            lim.set('lower', repr(-2 * math.pi))
            lim.set('upper', repr(2 * math.pi))
    # the hand on its own link, link 6 turned by pi about x: its z out of the hand, as every
    # hand's root (Kinova's link 6 has z pointing back into the wrist), so that the hand fits
    # any arm's flange; what hung from link 6 is turned with it
    link6 = links[PREFIX + 'link_6']
    hand = ET.Element('link', name=HAND)
    for child in list(link6):
        link6.remove(child)
        _flip(child)
        hand.append(child)
    for j in joints.values():
        if j.find('parent').get('link') == PREFIX + 'link_6':
            j.find('parent').set('link', HAND)
            _flip(j)
    hand_links = {HAND} | {n for n in links if 'finger' in n}
    for name in hand_links - {HAND}:
        # Kinova gives each finger link 10 g and 1e-7 kg m2: PyBullet's finger motors, whose
        # torque on a blocked finger grows with the link's inertia, then squeeze an object with
        # 0.1 N m and the grasp check feels nothing (80 g: 0.3-0.6 N m, objects slipped after
        # the lift); 200 g (inertia scaled alike) squeezes with 0.4-1.0 N m
        inertial = links[name].find('inertial')
        scale = FINGER_MASS / float(inertial.find('mass').get('value'))
        inertial.find('mass').set('value', repr(FINGER_MASS))
        inertia = inertial.find('inertia')
        for key, value in inertia.attrib.items():
            inertia.set(key, repr(float(value) * scale))
    arm = ET.Element('robot', name='kinova_jaco')
    hand_robot = ET.Element('robot', name='jaco_three_finger')
    for e in root:
        if e.tag == 'link':
            (hand_robot if e.get('name') in hand_links else arm).append(e)
        elif e.tag == 'joint':
            (hand_robot if e.find('parent').get('link') in hand_links else arm).append(e)
    hand_robot.insert(0, hand)
    for j in list(hand_robot.findall('joint')):     # the hand link first, then its fingers
        hand_robot.remove(j)
        hand_robot.append(j)
    # meshes: decimated binary STL, relative to the URDF
    urdf_dir = out_dir / 'urdf'
    for tree, folder in ((arm, 'kinova_jaco'), (hand_robot, 'jaco_three_finger')):
        meshes = out_dir / 'meshes' / folder
        meshes.mkdir(parents=True, exist_ok=True)
        (meshes / 'LICENSE').write_text(licence, encoding='utf-8')
        for mesh in tree.iter('mesh'):
            stem = Path(mesh.get('filename')).stem
            target = meshes / f'{stem}.stl'
            if not target.is_file():
                loaded = trimesh.load(str(kinova_dir / 'kinova_description' / 'meshes'
                                          / f'{stem}.STL'), force='mesh')
                if len(loaded.faces) > FACES:
                    loaded = loaded.simplify_quadric_decimation(face_count=FACES)
                loaded.export(str(target))
            mesh.set('filename', Path(os.path.relpath(target, urdf_dir)).as_posix())
    for tree, file, what in ((arm, 'kinova_jaco_arm.urdf', 'Kinova Jaco 2 arm, six joints'),
                             (hand_robot, 'jaco_three_finger.urdf',
                              'Kinova Jaco three-finger hand (KG-3)')):
        ET.indent(tree)
        (urdf_dir / file).write_text(_header(licence, what) + ET.tostring(tree, encoding='unicode')
                                     + '\n', encoding='utf-8')


if __name__ == '__main__':
    if len(sys.argv) != 4:
        print(__doc__, file=sys.stderr)
        raise SystemExit(2)
    main(*sys.argv[1:])
