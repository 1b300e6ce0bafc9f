"""A velocity command of the wrong length is refused with a line that fits any robot (it names
no particular robot's joints)."""

from __future__ import annotations

import pytest

from mindgrasp_sim.control import validate_velocities
from mindgrasp_sim.errors import SimError


@pytest.mark.parametrize('n_joints', [6, 7])
def test_wrong_length_names_the_count_and_the_order(n_joints):
    with pytest.raises(SimError) as info:
        validate_velocities([0.1, 0.2], n_joints)
    assert str(info.value) == (
        f'Joint velocity command has 2 values but the arm has {n_joints} joints; send '
        f'{n_joints} velocities in rad/s, one per arm joint in the order of /joint_states.')
    assert validate_velocities([0.0] * n_joints, n_joints).shape == (n_joints,)
