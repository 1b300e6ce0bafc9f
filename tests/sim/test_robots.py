"""Arms and hands as separate descriptions joined by a mount (mindgrasp_common.robot_description):
the shipped pairs give PyBullet the same bodies as the single URDFs they were cut from (so their
records stay the same), any arm takes any hand, and a bad pair names its fault in one line."""

from __future__ import annotations

import itertools
from pathlib import Path

import numpy as np
import pybullet_data
import pytest
import yaml

from mindgrasp_common.resources import resource_path
from mindgrasp_common.robot_description import (
    RobotDescriptionError,
    arm_names,
    hand_names,
    load_robot,
)
from mindgrasp_sim.camera import CameraConfig
from mindgrasp_sim.pybullet_quiet import pb
from mindgrasp_sim.robot_model import FILES
from mindgrasp_sim.simulation import Simulation

#: the single URDFs the shipped pairs were cut from
ORIGINALS = {
    'mindgrasp_arm': resource_path('mindgrasp_sim', 'urdf', 'mindgrasp_arm.urdf'),
    'xarm6': Path(pybullet_data.getDataPath()) / 'xarm' / 'xarm6_with_gripper.urdf',
    'panda': Path(pybullet_data.getDataPath()) / 'franka_panda' / 'panda.urdf',
}


def _body(urdf: Path) -> tuple:
    """What PyBullet makes of a URDF: joint infos, dynamics, visual and collision shapes."""
    c = pb.connect(pb.DIRECT)
    try:
        flags = (pb.URDF_USE_INERTIA_FROM_FILE | pb.URDF_USE_SELF_COLLISION
                 | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT)
        b = pb.loadURDF(str(urdf), useFixedBase=True, flags=flags, physicsClientId=c)
        n = pb.getNumJoints(b, physicsClientId=c)
        return ([pb.getJointInfo(b, j, physicsClientId=c)[:17] for j in range(n)],
                [pb.getDynamicsInfo(b, j, physicsClientId=c) for j in range(-1, n)],
                [v[1:8] for v in pb.getVisualShapeData(b, physicsClientId=c)],
                [pb.getCollisionShapeData(b, j, physicsClientId=c) for j in range(-1, n)])
    finally:
        pb.disconnect(c)


@pytest.mark.parametrize('name', sorted(ORIGINALS))
def test_a_shipped_pair_is_the_body_it_was_cut_from(name):
    """Same links in the same order, same joints, masses, inertias, collision shapes, and the
    same visual shapes but for the xArm6's decimated visual meshes (same links, frames, colours,
    other files)."""
    robot = load_robot(name)
    assert robot.arm is not None and robot.hand is not None
    joined, original = _body(robot.urdf), _body(ORIGINALS[name])
    for what, a, b in zip(('joints', 'dynamics', 'visuals', 'collisions'), joined, original,
                          strict=True):
        if what == 'visuals' and name == 'xarm6':
            # (link, geometry type, scale, file, frame position, frame orientation, colour)
            a, b = [[v[:3] + v[4:] for v in vs] for vs in (a, b)]
        assert a == b, f'{name}: the joined URDF differs in its {what}'


@pytest.mark.parametrize('name', sorted(ORIGINALS))
def test_the_wrist_camera_sees_the_same_with_links_left_out(name):
    """The links the camera leaves out of a frame (outside its view) change no pixel."""
    rng = np.random.default_rng(0)
    with Simulation('set_locations', seed=0, robot=name, camera=CameraConfig(64, 64)) as sim:
        for _ in range(8):
            sim.set_joint_positions(sim.home_pose + rng.normal(0.0, 0.4, sim.n_joints))
            culled = sim.render_camera(exact=True)
            sim._cull_enabled = False
            full = sim.render_camera(exact=True)
            sim._cull_enabled = True
            for a, b in zip(culled, full, strict=True):
                np.testing.assert_array_equal(a, b)


def test_the_shipped_arm_files_are_the_generated_ones():
    for file, build in FILES.items():
        committed = resource_path('mindgrasp_sim', 'urdf', file).read_text(encoding='utf-8')
        assert committed == build(), f'regenerate {file}: python -m mindgrasp_sim.robot_model ' \
                                     '--write config/robots/urdf'


@pytest.mark.slow
@pytest.mark.parametrize(('arm', 'hand'), list(itertools.product(arm_names(), hand_names())))
def test_any_arm_takes_any_hand(arm, hand):
    """Every shipped arm with every shipped hand loads, holds still, closes its hand and renders
    its wrist camera."""
    robot = load_robot(f'{arm}+{hand}')
    assert robot.arm_joints == robot.arm.joints and robot.gripper == robot.hand.gripper
    with Simulation('set_locations', seed=0, robot=robot, camera=CameraConfig(32, 32)) as sim:
        sim.set_gripper(1.0)
        sim.step(240)
        np.testing.assert_allclose(sim.joint_positions(), robot.home_pose, atol=0.02)
        closure = (sim.finger_positions() - np.array(robot.gripper.open)) / (
            np.array(robot.gripper.closed) - np.array(robot.gripper.open))
        # 1 s: the fingers' velocity limits let them close most of the way (0.8 of the
        # shipped hand's closure, the others' full)
        assert np.all(closure > 0.6), f'{arm}+{hand}: the hand did not close ({closure})'
        rgb, depth = sim.render_camera()
        assert rgb.shape == (32, 32, 3) and np.isfinite(depth).all()


def _pair(tmp_path: Path, hand_edit=None, **robot) -> Path:
    """A robot YAML joining the shipped xArm6 with a copy of the xArm gripper's description
    (``hand_edit(data)`` applied), with ``robot`` keys added."""
    hand = yaml.safe_load(resource_path('mindgrasp_sim', 'robots', 'hands',
                                        'xarm_gripper.yaml').read_text(encoding='utf-8'))
    hand['urdf'] = str(resource_path('mindgrasp_sim', 'urdf', 'xarm_gripper.urdf'))
    if hand_edit:
        hand_edit(hand)
    (tmp_path / 'hand.yaml').write_text(yaml.safe_dump(hand), encoding='utf-8')
    path = tmp_path / 'robot.yaml'
    path.write_text(yaml.safe_dump({'name': 'mine', 'arm': 'xarm6', 'hand': 'hand.yaml',
                                    **robot}), encoding='utf-8')
    return path


def test_a_pair_of_ones_own_files(tmp_path):
    robot = load_robot(_pair(tmp_path, mount={'joint': 'my_mount', 'xyz': [0, 0, 0.01]}))
    assert robot.name == 'mine' and robot.hand.path == tmp_path / 'hand.yaml'
    text = robot.urdf.read_text(encoding='utf-8')
    assert '<joint name="my_mount" type="fixed">' in text and 'package://' not in text


@pytest.mark.parametrize(('hand_edit', 'robot', 'message'), [
    (lambda h: h.update(joints=['drive_joint', 'left_finger']), {},
     r"Hand description '.*hand.yaml': the gripper joints name the joint 'left_finger', which "
     'the URDF xarm_gripper.urdf lacks; use one of its joints'),
    (None, {'arm': 'ur5'}, "No arm is named 'ur5'; use one of"),
    (None, {'mount': {'link': 'link9'}}, "the mount link 'link9' is not a link of the URDF "
                                         'xarm6_arm.urdf'),
    (None, {'home': [0.0] * 7}, r'arm: home must be 6 finite numbers'),
    (lambda h: h['tcp'].update(link='tool0'), {}, "the tcp link 'tool0' is not a link of the "
                                                  'URDF xarm_gripper.urdf'),
])
def test_a_bad_pair_names_its_fault_in_one_line(tmp_path, hand_edit, robot, message):
    with pytest.raises(RobotDescriptionError, match=message) as err:
        load_robot(_pair(tmp_path, hand_edit, **robot))
    assert '\n' not in str(err.value)


def test_a_hand_says_how_the_controller_holds_each_shape(tmp_path):
    """A hand's grasp: section sets the controller's per-shape parameters with robot:= (the
    robot YAML's own grasp: over the hand's); a name the controller lacks, or a value out of
    its range, is refused in one line."""
    from mindgrasp_fsm.errors import FsmError
    from mindgrasp_fsm.params import FsmParams

    def holds(h):
        h['grasp'] = {'sphere_grasp_height_fraction': 0.45, 'cube_close_force': 35}
    path = _pair(tmp_path, holds, grasp={'cube_close_force': 50})
    robot = load_robot(path)
    assert robot.hand.grasp == (('cube_close_force', 35.0), ('sphere_grasp_height_fraction',
                                                             0.45))
    assert dict(robot.grasp) == {'cube_close_force': 50.0, 'sphere_grasp_height_fraction': 0.45}
    params = FsmParams(robot=str(path))
    assert (params.sphere_grasp_height_fraction, params.cube_close_force) == (0.45, 50.0)
    assert FsmParams().sphere_grasp_height_fraction == 0.6      # without robot:= as before
    # a value given otherwise (a parameter file, -p, a live change) wins over the hand's
    assert FsmParams(robot=str(path), sphere_grasp_height_fraction=0.7
                     ).sphere_grasp_height_fraction == 0.7
    for grasp, message in (({'sphere_squeeze': 1.0}, "sets the grasp parameter 'sphere_squeeze', "
                                                     'which the controller does not have'),
                           ({'sphere_grasp_height_fraction': 2.0}, 'must be within'),
                           ({'tool_link': 1.0}, "grasp parameter 'tool_link'")):
        folder = tmp_path / next(iter(grasp))      # descriptions are cached by path
        folder.mkdir()
        with pytest.raises(FsmError, match=message) as err:
            FsmParams(robot=str(_pair(folder, grasp=grasp)))
        assert '\n' not in str(err.value)
    with pytest.raises(RobotDescriptionError, match="'grasp' must map controller parameters"):
        (tmp_path / 'words').mkdir()
        load_robot(_pair(tmp_path / 'words', grasp={'sphere_grasp_height_fraction': 'x'}))


def test_a_hand_whose_names_clash_with_the_arm(tmp_path):
    def arm_as_hand(h):       # the arm's own URDF as the hand: every name clashes
        h.update(urdf=str(resource_path('mindgrasp_sim', 'urdf', 'xarm6_arm.urdf')),
                 joints=['joint1'], open=0.0, closed=0.1)
        h['tcp']['link'] = h['camera']['link'] = 'link6'
    with pytest.raises(RobotDescriptionError, match=r"both URDFs have a link named '.*'; rename "
                                                    r'it in one of them'):
        load_robot(_pair(tmp_path, arm_as_hand))


def test_a_turned_flange_turns_its_joint_axis_with_it():
    """The Jaco's hand root replaces its link 6 turned by pi about x (z out of the hand): joint
    6's axis, written in its child's frame, is turned alike, so the joint still turns the hand
    as Kinova's description does (the camera at home where the xArm6's is)."""
    import xml.etree.ElementTree as ET

    robot = load_robot('jaco')
    joint = next(j for j in ET.parse(str(robot.urdf)).getroot().findall('joint')
                 if j.get('name') == 'j2n6s300_joint_6')
    assert joint.find('child').get('link') == robot.hand_root == 'j2n6s300_link_hand'
    assert [float(v) for v in joint.find('axis').get('xyz').split()] == [0.0, 0.0, -1.0]
    with Simulation('set_locations', seed=0, robot=robot) as sim:
        pos, orn = sim.camera_pose()
    np.testing.assert_allclose(pos, [0.297, 0.0, 0.621], atol=0.005)
    x_axis = np.array(pb.getMatrixFromQuaternion(orn)).reshape(3, 3)[:, 0]
    np.testing.assert_allclose(x_axis, [0.0, -1.0, 0.0], atol=0.01)
