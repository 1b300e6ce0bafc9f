"""The prompters' parameters (GrazParams, TrainerParams): only the live ones are writable,
cross-field checks name the fix;
in a running node ``mindgrasp param describe`` shows the descriptors and a bad value ends the
process with exit code 2 and one line naming the parameter."""

from __future__ import annotations

import subprocess
import sys

import pytest

from mindgrasp_common.robot_description import robot_names
from mindgrasp_ros.params import ParameterError, describe, from_mapping
from mindgrasp_trainer.graz_node import GrazParams
from mindgrasp_trainer.trainer_node import TrainerParams

#: node name, its parameter dataclass, its module, the parameters it changes while running
NODES = [
    ('graz_prompter', GrazParams, 'mindgrasp_trainer.graz_node', {'feedback', 'max_certainty'}),
    ('trainer', TrainerParams, 'mindgrasp_trainer.trainer_node', {'reset_timeout'}),
]
IDS = [n[0] for n in NODES]


# the parameter file and the descriptions: tests/ros/test_node_params.py, with every node


@pytest.mark.parametrize(('node', 'cls', 'module', 'live'), NODES, ids=IDS)
def test_only_the_live_parameters_can_change_while_it_runs(node, cls, module, live):
    assert {name for name, (_, desc) in describe(cls).items() if not desc.read_only} == live


@pytest.mark.parametrize(('cls', 'values', 'match'), [
    (GrazParams, {'rest_min': 3.0, 'rest_max': 2.0},
     r"'rest_min' \(3.0 s\) is larger than 'rest_max' \(2.0 s\); swap them"),
    (GrazParams, {'classes': [0, 0]}, r"'classes' \[0, 0\] has duplicates; list each class once"),
    (GrazParams, {'classes': []}, r"'classes' is empty; give at least one class index"),
    (GrazParams, {'feedback': 'loud'}, r"'feedback' is 'loud'; use one of off, move, always"),
    (GrazParams, {'n_trials': -3}, r"'n_trials' must be within \[1, 100000\]; -3 is invalid"),
    (TrainerParams, {'classes': [4]}, r"'classes' holds \[4\], which are not class indices"),
    (TrainerParams, {'approach_joint': 6},
     r"'approach_joint' is 6, outside the 6 arm joints of the robot 'mindgrasp_arm'; use an "
     r'index from 0 to 5'),
    (TrainerParams, {'turn_joint': 6, 'robot': 'xarm6'},
     r"'turn_joint' is 6, outside the 6 arm joints of the robot 'xarm6'"),
    (TrainerParams, {'robot': 'ur5'},
     r"No robot is named 'ur5'; use one of \[.*'xarm6'.*\] or the path of a robot YAML"),
    (TrainerParams, {'reset_timeout': 0.0}, r"'reset_timeout' must be within \[0.001, 3600\] s"),
])
def test_bad_values_name_the_parameter_and_the_fix(cls, values, match):
    with pytest.raises(ParameterError, match=match):
        from_mapping(cls, values)


def _mindgrasp(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.slow
def test_running_prompters_show_their_descriptors(spawn_node):
    graz = spawn_node('mindgrasp_trainer.graz_node', display_rate=0.0, duration=300.0)
    # robot_timeout 0: waits for the training robot as long as the test needs
    trainer = spawn_node('mindgrasp_trainer.trainer_node', robot_timeout=0.0)
    assert graz.wait_for_output('Graz-BCI session:', 60), graz.output()
    assert trainer.wait_for_output('MIndGrasp Trainer:', 60), trainer.output()
    out = _mindgrasp('param', 'describe', '/graz_prompter', 'n_trials', 'fixation', 'feedback')
    assert out.returncode == 0, out.stderr
    assert 'Parameter name: n_trials\n  Type: integer\n  Description: total trials; a multiple ' \
        'of len(classes) gives exact balance\n  Constraints:\n    Read only: true\n' \
        '    Min value: 1\n    Max value: 100000' in out.stdout, out.stdout
    assert 'Description: fixation cross before the cue [s]' in out.stdout, out.stdout
    assert 'Additional constraints: one of: off, move, always; live: applied at once' \
        in out.stdout, out.stdout
    out = _mindgrasp('param', 'describe', '/trainer', 'turn_speed', 'reset_timeout')
    assert out.returncode == 0, out.stderr
    assert 'Parameter name: turn_speed\n  Type: double\n  Description: velocity of ' \
        "'turn_joint' for left hand (+) / right hand (-) [rad/s]\n  Constraints:\n" \
        '    Read only: true\n    Min value: -10.0\n    Max value: 10.0' in out.stdout, out.stdout
    assert 'Parameter name: reset_timeout' in out.stdout and \
        'Additional constraints: live: applied at once' in out.stdout, out.stdout
    # a read-only parameter is refused with the reason, a live one is applied
    out = _mindgrasp('param', 'set', '/trainer', 'n_trials', '8')
    assert out.returncode == 1 and "'n_trials' is read-only" in out.stderr, out.stderr
    out = _mindgrasp('param', 'set', '/trainer', 'reset_timeout', '2.5')
    assert out.returncode == 0 and 'Set parameter successful' in out.stdout, out.stderr
    assert trainer.wait_for_output('Parameter change applied: reset_timeout=2.5', 60), \
        trainer.output()


@pytest.mark.slow
@pytest.mark.parametrize(('module', 'params', 'message'), [
    ('mindgrasp_trainer.graz_node', {'n_trials': -3},
     "[GrazNode] ERROR: Invalid value -3 for parameter 'n_trials': must be within [1, 100000]"),
    ('mindgrasp_trainer.trainer_node', {'n_trials': -3},
     "[TrainerNode] ERROR: Invalid value -3 for parameter 'n_trials': must be within [1, "
     '100000]'),
    ('mindgrasp_trainer.trainer_node', {'turn_joint': 6},
     "[TrainerNode] ERROR: 'turn_joint' is 6, outside the 6 arm joints of the robot "
     "'mindgrasp_arm'; use an index from 0 to 5."),
    ('mindgrasp_trainer.trainer_node', {'robot': 'ur5'},
     f"[TrainerNode] ERROR: No robot is named 'ur5'; use one of {robot_names()} or the path of "
     'a robot YAML file (robot:=path/to/robot.yaml).'),
], ids=['graz-n_trials', 'trainer-n_trials', 'trainer-turn_joint', 'trainer-robot'])
def test_bad_value_ends_the_process_with_exit_2_and_one_line(spawn_node, module, params, message):
    proc = spawn_node(module, **params)
    assert proc.wait(60) == 2, proc.output()
    lines = [line for line in proc.output().splitlines() if line.strip()]
    assert lines == [message], lines
