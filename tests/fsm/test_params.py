"""Controller parameters: the ROS parameter file, validation messages."""

from __future__ import annotations

import pytest

from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.params import FsmParams, default_params_path


def test_parameter_file_holds_every_parameter_with_the_defaults() -> None:
    import yaml

    from mindgrasp_common.robot_description import load_robot
    from mindgrasp_fsm.params import ROBOT_PARAMETERS

    data = yaml.safe_load(default_params_path().read_text())
    # the robot's parameters come from its description, not from the controller's file
    assert set(data['fsm']['ros__parameters']) == set(FsmParams.names()) - set(ROBOT_PARAMETERS)
    assert not set(data['fsm']['ros__parameters']) & set(ROBOT_PARAMETERS)
    assert FsmParams.from_yaml(default_params_path()) == FsmParams()
    shipped = FsmParams(robot='mindgrasp_arm')
    assert all(getattr(FsmParams(), name) == getattr(shipped, name) for name in ROBOT_PARAMETERS)
    assert FsmParams().joint_names == list(load_robot('mindgrasp_arm').arm_joints)


@pytest.mark.parametrize(('values', 'match'), [
    ({'home_position': [0.0] * 5}, r"'home_position' must have 6 entries"),
    ({'lock_duration': 0.0}, r"'lock_duration' must be a positive number"),
    ({'watchdog_timeout': -1.0}, r"'watchdog_timeout' must be a positive number"),
    ({'joint_lower_limits': [1.0] * 6, 'joint_upper_limits': [0.0] * 6},
     r'Joint 1 has lower limit 1.0 >= upper limit 0.0'),
    ({'approach_joint': 7}, r"'approach_joint' must be a joint number 1..6"),
    ({'recenter_threshold': 0.01}, r"'recenter_threshold' .* must exceed 'center_tolerance'"),
    ({'max_joint_velocity': [1.0, 1.0, 0.0, 1.0, 1.0, 1.0]}, r"'max_joint_velocity' must be > 0"),
    ({'grasp_retries': -1}, r"'grasp_retries' must be >= 0"),
    ({'measure_frames': 0}, r"'measure_frames' must be >= 1 camera frame"),
    ({'watchdog_timout': 0.3}, r"Unknown controller parameter\(s\) \['watchdog_timout'\]"),
])
def test_bad_parameters_name_the_problem(values: dict, match: str) -> None:
    with pytest.raises(FsmError, match=match):
        FsmParams.from_dict(values)


def test_parameter_file_errors(tmp_path) -> None:
    f = tmp_path / 'p.yaml'
    f.write_text('other_node:\n  ros__parameters: {}\n')
    with pytest.raises(FsmError, match=r"has no 'fsm: ros__parameters:' section"):
        FsmParams.from_yaml(f)
    f.write_text('fsm: [unclosed\n')
    with pytest.raises(FsmError, match='Cannot read the controller parameter file'):
        FsmParams.from_yaml(f)
    f.write_text('/**:\n  ros__parameters:\n    lock_duration: 2.0\n')
    assert FsmParams.from_yaml(f).lock_duration == 2.0


def test_per_shape_values() -> None:
    p = FsmParams(sphere_grasp_height_fraction=0.4)
    assert p.shape_value('sphere', 'grasp_height_fraction') == 0.4
    assert p.shape_value('unknown', 'approach_height') == p.cube_approach_height


def test_missing_robot_model_is_named() -> None:
    from mindgrasp_fsm.grasp_fsm import GraspFsm

    with pytest.raises(FsmError, match=r'Cannot read the robot description .*nope\.urdf'):
        GraspFsm.from_params(FsmParams(urdf_file='/nonexistent/nope.urdf'))
    with pytest.raises(FsmError, match=r"The link 'gripper_tip' is not in"):
        GraspFsm.from_params(FsmParams(tool_link='gripper_tip'))
