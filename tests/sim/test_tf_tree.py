"""TfTree: the transforms robot_state_publisher makes of the URDF, against PyBullet's forward
kinematics of the same URDF."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mindgrasp_sim.errors import SimError
from mindgrasp_sim.tf_tree import TfTree


def _same_rotation(a: np.ndarray, b: np.ndarray) -> float:
    """Angle (rad) between two xyzw quaternions."""
    return float((Rotation.from_quat(a).inv() * Rotation.from_quat(b)).magnitude())


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_tree_matches_pybullet_forward_kinematics(sim, seed: int) -> None:
    tree = TfTree(sim.urdf.read_text(encoding='utf-8'))
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1.2, 1.2, 6)
    positions = dict(zip(sim.joint_names, q, strict=True))
    for link, name in (('tcp', 'tcp'), ('camera', 'camera_color_optical_frame')):
        want_pos, want_quat = sim.forward_kinematics(q, link)
        pos, quat = tree.pose(tree.root, name, positions)
        np.testing.assert_allclose(pos, want_pos, atol=1e-6)
        assert _same_rotation(quat, want_quat) < 1e-6


def test_moving_and_fixed_joints_split_as_robot_state_publisher(sim) -> None:
    tree = TfTree(sim.urdf.read_text(encoding='utf-8'))
    assert tree.root == 'base_link'
    assert tree.moving_joints == [*sim.joint_names, *sim.finger_names]
    static = {(t.parent, t.child) for t in tree.static_transforms()}
    assert ('palm', 'camera_color_optical_frame') in static and ('palm', 'tcp') in static
    moving = tree.transforms({'joint_1': 0.5})   # only joints with a position
    assert [(t.parent, t.child) for t in moving] == [('base_link', 'link_1')]
    np.testing.assert_allclose(moving[0].rotation, Rotation.from_euler('z', 0.5).as_quat(),
                               atol=1e-12)


def test_prismatic_joint_translates_along_its_axis() -> None:
    urdf = ('<robot name="r"><link name="a"/><link name="b"/>'
            '<joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>'
            '<origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/><axis xyz="1 0 0"/></joint>'
            '</robot>')
    pos, _ = TfTree(urdf).pose('a', 'b', {'slide': 0.2})
    np.testing.assert_allclose(pos, [0.0, 0.2, 1.0], atol=1e-12)


@pytest.mark.parametrize(('urdf', 'message'), [
    ('<robot><link', 'not valid XML'),
    ('<model/>', 'not <robot>'),
    ('<robot><link name="a"/><link name="b"/></robot>', 'one root link'),
    ('<robot><link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/>'
     '<child link="b"/><origin xyz="0 0"/></joint></robot>', 'three numbers'),
])
def test_bad_description_names_the_problem(urdf: str, message: str) -> None:
    with pytest.raises(SimError, match=message):
        TfTree(urdf)
