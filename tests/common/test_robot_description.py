"""Robot descriptions (mindgrasp_common.robot_description): the shipped ones load and agree with
their URDFs, and every bad description gives one line naming the problem and the fix."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest
import yaml

from mindgrasp_common import robot
from mindgrasp_common.resources import resolve_path
from mindgrasp_common.robot_description import RobotDescriptionError, load_robot, robot_names

#: the xArm6 in the single-URDF format (arm and hand in one URDF), as it shipped before the
#: arm + hand split: the format stays valid for a lab's combined URDF
SINGLE_XARM6 = {
    'name': 'xarm6', 'urdf': 'package://pybullet_data/xarm/xarm6_with_gripper.urdf',
    'licence': 'URDF and meshes by UFactory (BSD-3-Clause)',
    'arm': {'joints': ['joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'joint6'],
            'home': [0.0, -0.86, -1.04, 0.0, 1.53, 0.0],
            'max_velocity': [1.0, 1.0, 1.3, 1.3, 1.6, 1.6]},
    'gripper': {'kind': 'parallel_jaw',
                'joints': ['drive_joint', 'left_finger_joint', 'left_inner_knuckle_joint',
                           'right_outer_knuckle_joint', 'right_finger_joint',
                           'right_inner_knuckle_joint'],
                'open': 0.0, 'closed': 0.85, 'grasp_check': 'width', 'self_collision': False},
    'tcp': {'link': 'xarm_gripper_base_link', 'xyz': [0.0, 0.0, 0.152]},
    'camera': {'link': 'xarm_gripper_base_link', 'xyz': [0.07, 0.0, 0.02],
               'rpy': [0.0, 0.0, 1.5707963267948966]},
}


def test_shipped_robots():
    assert robot_names() == ['iiwa_franka_hand', 'iiwa_mindgrasp_hand', 'iiwa_xarm_gripper',
                             'jaco', 'mindgrasp_arm', 'panda', 'xarm6']
    arm = load_robot()
    assert arm.arm_joints == robot.ARM_JOINTS and arm.home_pose == robot.HOME_POSE
    assert arm.gripper.kind == 'multi_finger' and arm.tcp_link == 'tcp'
    assert (arm.arm.name, arm.hand.name, arm.hand_root) == ('mindgrasp_arm', 'mindgrasp_hand',
                                                            'palm')
    xarm = load_robot('xarm6')
    assert xarm.urdf.suffix == '.urdf' and xarm.urdf.is_file()
    assert (xarm.arm.name, xarm.hand.name, xarm.mount.link) == ('xarm6', 'xarm_gripper', 'link6')
    assert xarm.gripper.kind == 'parallel_jaw' and len(xarm.gripper.joints) == 6
    assert xarm.camera.link == 'xarm_gripper_base_link' and xarm.camera.xyz != (0.0, 0.0, 0.0)
    assert xarm.lower[1] == pytest.approx(-2.059) and xarm.max_velocity[0] == 1.0
    assert 'BSD-3-Clause' in xarm.licence
    assert load_robot(xarm.path) is xarm     # a path works as well as a name
    panda = load_robot('panda')
    assert len(panda.arm_joints) == 7 and panda.mount.rpy[2] == pytest.approx(-math.pi / 4)
    # the hand's two prismatic fingers: the second a URDF mimic of the first
    assert panda.gripper.joints == ('panda_finger_joint1', 'panda_finger_joint2')
    assert panda.gripper.mimic == (('panda_finger_joint2', 'panda_finger_joint1', 1.0, 0.0),)
    assert panda.gripper.open == (0.04, 0.04) and panda.gripper.closed == (0.0, 0.0)
    assert 'Apache-2.0' in panda.licence


def test_the_shipped_arm_constants_are_the_description():
    """The module constants keep their values (records of the shipped arm stay the same)."""
    assert tuple(f'joint_{i}' for i in range(1, 7)) == robot.ARM_JOINTS
    assert robot.ARM_LOWER_LIMITS == (-3.05, -1.75, -2.6, -2.6, -2.4, -3.05)
    assert robot.ARM_MAX_VELOCITY == (1.0, 1.0, 1.3, 1.3, 1.6, 1.6)
    assert robot.ARM_EFFORT == (60.0, 80.0, 40.0, 30.0, 12.0, 6.0)
    assert (robot.FINGER_LOWER_LIMIT, robot.FINGER_UPPER_LIMIT) == (-0.6, 1.3)
    assert (robot.FINGER_OPEN, robot.FINGER_CLOSED) == (-0.55, 1.25)
    assert Path(robot.URDF_URI).is_file()      # the joined arm + hand URDF


def _variant(tmp_path: Path, edit) -> Path:
    """A copy of the single-URDF xArm6 description with ``edit(data)`` applied."""
    data = copy.deepcopy(SINGLE_XARM6)
    edit(data)
    path = tmp_path / 'my_arm.yaml'
    path.write_text(yaml.safe_dump(data), encoding='utf-8')
    return path


def _set(section: str | None, key: str, value):
    def edit(data):
        (data if section is None else data[section])[key] = value
    return edit


def _no_limit_urdf(tmp_path: Path):
    urdf = resolve_path(SINGLE_XARM6['urdf'], 'mindgrasp_sim').read_text(encoding='utf-8').replace(
        '<limit effort="50" lower="0" upper="0.85" velocity="2"/>\n    <mimic', '<mimic')
    (tmp_path / 'no_limits.urdf').write_text(urdf, encoding='utf-8')
    return _set(None, 'urdf', 'no_limits.urdf')


@pytest.mark.parametrize(('edit', 'message'), [
    (_set('arm', 'joints', ['joint1', 'joint2', 'joint3', 'joint4', 'joint5']),
     'the arm has 5 joints .* MIndGrasp drives arms of 6 or 7 joints'),
    (_set('arm', 'joints', ['joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'joint_6']),
     "the arm joints name the joint 'joint_6', which the URDF xarm6_with_gripper.urdf lacks; "
     'use one of its joints'),
    (_set('arm', 'joints', ['joint1', 'joint2', 'joint3', 'joint4', 'joint5', 'gripper_fix']),
     "'gripper_fix', a fixed joint .* name moving"),
    (_set('arm', 'home', [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
     r"home position 1.0 rad of 'joint3' is outside its URDF limits \[-3.927, 0.19198\]"),
    (_set('arm', 'home', [0.0, 0.0]), r'arm: home must be 6 finite numbers'),
    (_set('arm', 'max_velocity', [5.0] * 6), r"max_velocity 5.0 rad/s of 'joint1' must be in"),
    (_set('gripper', 'kind', 'suction'), "gripper kind 'suction' is not one of"),
    (_set('gripper', 'grasp_check', 'vibes'), "grasp_check 'vibes' is not one of"),
    (_set('gripper', 'self_collision', 'no'), "self_collision must be true or false, got 'no'"),
    (_set('gripper', 'closed', 2.0), r'open 0.0 and closed 2.0 of .* must lie in its URDF'),
    (_set('camera', 'link', 'camera_link'),
     "the camera link 'camera_link' is not a link of the URDF xarm6_with_gripper.urdf; name one"),
    (_set('tcp', 'link', 'tool0'), "the tcp link 'tool0' is not a link of the URDF"),
    (lambda data: data.pop('camera'), "the key 'camera' is missing; add it"),
    (_set(None, 'urdf', 'package://pybullet_data/xarm/nope.urdf'), "has no data file"),
])
def test_bad_descriptions_name_the_problem_and_the_fix(tmp_path, edit, message):
    path = _variant(tmp_path, edit)
    with pytest.raises(RobotDescriptionError, match=message) as err:
        load_robot(path)
    assert '\n' not in str(err.value) and str(path) in str(err.value)


def test_a_gripper_without_limits(tmp_path):
    path = _variant(tmp_path, _no_limit_urdf(tmp_path))
    with pytest.raises(RobotDescriptionError, match="the gripper joint 'left_finger_joint' has no "
                       r'position, velocity and effort limits .* add <limit'):
        load_robot(path)


@pytest.mark.parametrize(('spec', 'message'), [
    ('ur5', r"No robot is named 'ur5'; use one of \['iiwa_franka_hand', .*'xarm6'\] or the path"),
    ('ur5+franka_hand', r"No arm is named 'ur5'; use one of \["),
    ('panda+claw', r"No hand is named 'claw'; use one of \["),
    ('missing/arm.yaml', "The robot description 'missing/arm.yaml' does not exist"),
])
def test_unknown_robots(spec, message):
    with pytest.raises(RobotDescriptionError, match=message):
        load_robot(spec)


def test_not_yaml(tmp_path):
    path = tmp_path / 'arm.yaml'
    path.write_text('arm: [unclosed\n', encoding='utf-8')
    with pytest.raises(RobotDescriptionError, match='is not readable YAML'):
        load_robot(path)
    path.write_text('- a list\n', encoding='utf-8')
    with pytest.raises(RobotDescriptionError, match='must be a YAML mapping'):
        load_robot(path)


@pytest.mark.parametrize('name', robot_names())
def test_the_arm_heading_is_where_the_camera_looks(name):
    """A subject node reads the arm's heading from the first joint (ArmHeading): it is the yaw of
    the camera's optical axis, by the URDF's forward kinematics, at home and turned either way
    (the Jaco's first joint turns the other way round and sits at 2.93 rad at home)."""
    import numpy as np

    from mindgrasp_common.arm_heading import ArmHeading
    from mindgrasp_fsm.grasp_fsm import GraspFsm
    from mindgrasp_fsm.params import FsmParams

    heading = ArmHeading.of_robot(name)
    kinematics = GraspFsm.from_params(FsmParams(robot=name)).kinematics
    home = np.array(load_robot(name).home_pose)
    assert heading.joint == load_robot(name).arm_joints[0] and heading.home == home[0]
    for turn in (-0.6, 0.0, 0.4):
        q = home.copy()
        q[0] += turn
        _, rotation = kinematics.camera_pose(q)
        looks = math.atan2(rotation[1, 2], rotation[0, 2])
        assert heading(q[0]) == pytest.approx(looks, abs=0.02), (turn, heading)
