"""Importing vendors' robot descriptions as MIndGrasp arms and hands (ROS-free; run once by a
maintainer, its output committed under ``config/robots/``).

- :func:`split_urdf` cuts a URDF that holds an arm with its hand into an arm URDF and a hand URDF
  at the fixed joint that carries the hand (the mount), keeping the elements in their order, so
  that the description joining them again (:func:`mindgrasp_common.urdf.merge_urdf`)
  gives PyBullet the same bodies;
- :func:`home_like` finds a home pose that puts a new pair's wrist camera where a shipped
  robot's is at home (``python -m mindgrasp_sim.robot_import home kuka_iiwa+franka_hand``);
- :func:`simplify_visual_meshes` writes decimated copies of a URDF's visual meshes (a face
  budget each; ``trimesh`` with ``fast-simplification``, installed only to import: ``pip install
  trimesh fast-simplification``) beside the description and points the URDF at them. Collision
  meshes stay as they are (the physics does not change); the wrist camera and the scene view
  draw fewer triangles (TinyRenderer's cost is per triangle: the xArm gripper's 50 000 took
  15 ms a frame).

Usage (the shipped xArm6 and Panda pairs; then ``simplify`` on the xArm6's two files)::

    python -m mindgrasp_sim.robot_import split \\
        package://pybullet_data/xarm/xarm6_with_gripper.urdf xarm_gripper_base_link \\
        config/robots/urdf/xarm6_arm.urdf config/robots/urdf/xarm_gripper.urdf
    python -m mindgrasp_sim.robot_import simplify config/robots/urdf/xarm_gripper.urdf \\
        config/robots/meshes/xarm_gripper 1500
"""

from __future__ import annotations

import copy
import os
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from mindgrasp_common.resources import resolve_path

__all__ = ['home_like', 'simplify_visual_meshes', 'split_urdf']


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


def simplify_visual_meshes(urdf: str | Path, out_dir: str | Path, faces: int = 1500) -> int:
    """Decimate each visual mesh of the URDF file ``urdf`` that has more than ``faces``
    triangles to about that many, write it as binary STL to ``out_dir`` (named after the
    source file) and point the URDF's ``<visual>`` at it, relative to the URDF. Returns the
    number of meshes replaced. Collision meshes are left alone."""
    import trimesh

    urdf, out_dir = Path(urdf), Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    text = urdf.read_text(encoding='utf-8')
    root = ET.fromstring(text)
    replaced = 0
    for visual in root.iter('visual'):
        mesh = visual.find('geometry/mesh')
        if mesh is None:
            continue
        name = mesh.get('filename', '')
        source = resolve_path(name, 'mindgrasp_sim') if name.startswith('package://') \
            else (urdf.parent / name)
        loaded = trimesh.load(str(source), force='mesh')
        if len(loaded.faces) <= faces:
            continue
        small = loaded.simplify_quadric_decimation(face_count=faces)
        target = out_dir / (Path(name).stem.lower() + '.stl')
        small.export(str(target))
        mesh.set('filename', Path(os.path.relpath(target.resolve(),
                                                  urdf.parent.resolve())).as_posix())
        replaced += 1
    head = text[:text.index('<robot')]          # the XML declaration and the origin comment
    urdf.write_text(head + ET.tostring(root, encoding='unicode') + '\n', encoding='utf-8')
    return replaced


def home_like(robot: str, reference: str = 'xarm6', iterations: int = 200) -> list[float]:
    """A home pose (n,) rad for the arm of ``robot`` (a robot spec, e.g. ``'kuka_iiwa+
    franka_hand'``) that puts its wrist camera where ``reference``'s is at its home, facing the
    same way, so the controller's search finds the objects as it does with the reference
    (PyBullet's damped least squares on the joined URDF, from and towards the arm's home)."""
    import numpy as np

    from mindgrasp_common.robot_description import load_robot
    from mindgrasp_sim.pybullet_quiet import pb
    from mindgrasp_sim.simulation import Simulation

    with Simulation('set_locations', robot=reference) as ref:
        cam_pos, cam_orn = ref.camera_pose()
    target = load_robot(robot)
    with Simulation('set_locations', robot=target) as sim:
        frame = target.camera
        inv_pos, inv_orn = pb.invertTransform(list(frame.xyz),
                                              pb.getQuaternionFromEuler(frame.rpy))
        link_pos, link_orn = pb.multiplyTransforms(cam_pos.tolist(), cam_orn.tolist(),
                                                   inv_pos, inv_orn)
        kin, body = sim.kinematic_twin
        mid = np.array(target.home_pose)         # the arm's own home: seed and rest pose
        q = mid.copy()
        movable = [j for j in range(kin.getNumJoints(body))
                   if kin.getJointInfo(body, j)[2] != pb.JOINT_FIXED]
        lower = [kin.getJointInfo(body, j)[8] for j in movable]
        upper = [kin.getJointInfo(body, j)[9] for j in movable]
        arm = [movable.index(j) for j in sim.arm_joint_indices]
        for _ in range(iterations):
            sim.set_twin_joints(q)
            sol = kin.calculateInverseKinematics(
                body, sim.camera_link_index, link_pos, link_orn, lowerLimits=lower,
                upperLimits=upper, jointRanges=[u - lo for u, lo in zip(upper, lower, strict=True)],
                restPoses=[float(mid[arm.index(i)]) if i in arm else 0.0
                           for i in range(len(movable))], maxNumIterations=100)
            q = np.clip(np.array([sol[i] for i in arm]), sim.lower, sim.upper)
        pos, _ = sim.forward_kinematics(q, 'camera')
        print(f'camera {np.round(pos, 3).tolist()} m, the reference\'s '
              f'{np.round(cam_pos, 3).tolist()} m', file=sys.stderr)
        return [round(float(v), 4) for v in q]


def main(argv: list[str] | None = None) -> int:
    """``split URDF HAND_ROOT ARM_OUT HAND_OUT`` (prints the mount) or
    ``simplify URDF OUT_DIR FACES``."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) in (2, 3) and args[0] == 'home':
        print(home_like(*args[1:]))
        return 0
    if len(args) == 4 and args[0] == 'simplify':
        print(simplify_visual_meshes(args[1], args[2], int(args[3])), 'meshes simplified')
        return 0
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
