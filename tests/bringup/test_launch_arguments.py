"""Launch arguments are checked before any process starts: one line naming the argument, the
value and the fix, exit 2, no run directory, no node started."""

from __future__ import annotations

import subprocess
import sys

import pytest

from mindgrasp_launch import LaunchError, LaunchService


@pytest.mark.parametrize(('args', 'message'), [
    (['seed:=abc'], "launch argument 'seed' is 'abc': a whole number >= 0 is expected"),
    (['seed:=-1'], "launch argument 'seed' is '-1': a whole number >= 0 is expected"),
    (['trials:=x'], "launch argument 'trials' is 'x': a whole number >= 0 is expected"),
    (['model:=/no/such/model.json'], "launch argument 'model' is '/no/such/model.json', which is "
                                     'not a file'),
    (['model:=package://mindgrasp_classifier/models/nope.json'],
     "launch argument 'model' is 'package://mindgrasp_classifier/models/nope.json', which is not "
     'a file'),
    (['subject:=telepathy'], "launch argument 'subject' got 'telepathy', which is not one of"),
])
def test_demo_arguments_are_checked_in_the_plan(args, message):
    with pytest.raises(LaunchError, match=message):
        LaunchService('demo', args).plan(strict=True)


@pytest.mark.parametrize(('profile', 'args', 'message'), [
    ('experiment', ['seed:=-1'], "'seed' is '-1': a whole number >= 0 is expected"),
    ('experiment', ['accuracy:=1.5'], "'accuracy' is '1.5': a number from 0 to 1 is expected"),
    ('experiment', ['accuracy:=nan'], "'accuracy' is 'nan': a number from 0 to 1 is expected"),
    ('experiment', ['first_trial:=0'], "'first_trial' is '0': a whole number >= 1 is expected"),
    ('experiment', ['model:=nope.json'], "'model' is 'nope.json', which is not a file"),
    ('sim', ['seed:=x'], "'seed' is 'x': a whole number >= 0 is expected"),
    ('sim', ['realism_seed:=1.5'], "'realism_seed' is '1.5': a whole number >= 0"),
    ('eeg', ['seed:=abc'], "'seed' is 'abc': a whole number >= 0 is expected"),
    ('eeg', ['duration:=-2'], "'duration' is '-2': a number >= 0 is expected"),
    ('trainer', ['trials:=0'], "'trials' is '0': a whole number >= 1 is expected"),
    ('graz', ['seed:=__import__'], "'seed' is '__import__': a whole number >= 0"),
])
def test_every_profile_checks_its_numbers(profile, args, message):
    with pytest.raises(LaunchError, match=message):
        LaunchService(profile, args).plan(strict=True)


#: the arguments a profile cannot start without
REQUIRED = {'hardware': ['eeg_stream:=amp', 'eeg_unpinned:=true', 'arm_driver:=true', 'model:=package://'
                         'mindgrasp_classifier/models/default_classifier.json'],
            'replay': ['bag:=runs/x']}


@pytest.mark.parametrize('profile', ['sim', 'demo', 'experiment', 'trainer', 'graz', 'hardware',
                                     'replay'])
def test_every_profile_checks_its_robot(profile, tmp_path):
    required = REQUIRED.get(profile, [])
    with pytest.raises(LaunchError, match=r"launch argument 'robot' is 'ur5': No robot is named "
                                          r"'ur5'; use one of \[.*'xarm6'.*\]"):
        LaunchService(profile, [*required, 'robot:=ur5']).plan(strict=True)
    bad = tmp_path / 'my_arm.yaml'
    bad.write_text('name: my_arm\nurdf: package://mindgrasp_sim/urdf/mindgrasp_arm.urdf\n'
                   'arm: {joints: [joint_1, joint_2, joint_3], home: [0, 0, 0]}\n')
    with pytest.raises(LaunchError, match=r"launch argument 'robot' is '.*my_arm.yaml': Robot "
                                          r'description .*: the arm has 3 joints'):
        LaunchService(profile, [*required, f'robot:={bad}']).plan(strict=True)


def test_a_robot_is_a_name_a_path_or_a_package_uri(tmp_path, monkeypatch):
    from mindgrasp_common.robot_description import load_robot

    monkeypatch.chdir(tmp_path)
    path = load_robot('xarm6').path
    for robot in ('xarm6', str(path), 'package://mindgrasp_sim/robots/xarm6.yaml'):
        plan = LaunchService('sim', [f'robot:={robot}']).plan(strict=True)
        assert load_robot(plan.processes[-1].parameters['robot']).path == path
    with pytest.raises(LaunchError, match=r"The robot description 'package://mindgrasp_sim/"
                                          r"robots/nope.yaml' does not exist"):
        LaunchService('sim', ['robot:=package://mindgrasp_sim/robots/nope.yaml']).plan(
            strict=True)


@pytest.mark.parametrize(('profile', 'argument', 'line'), [
    ('demo', 'seed:=abc', "launch argument 'seed' is 'abc': a whole number >= 0 is expected, "
                          'e.g. seed:=3.'),
    ('trainer', 'robot:=ur5', "launch argument 'robot' is 'ur5': No robot is named 'ur5'; use "
                              'one of '),
])
def test_bad_argument_starts_nothing_and_exits_2(tmp_path, profile, argument, line):
    run_dir = tmp_path / 'run'
    out = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'launch', profile,
                          argument, '--run-dir', str(run_dir)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f'mindgrasp launch: error: {line}'), out.stderr
    assert not run_dir.exists() and not out.stdout.strip()


def test_good_arguments_pass():
    plan = LaunchService('demo', ['seed:=4', 'trials:=0', 'model:=']).plan(strict=True)
    assert {p.label for p in plan.processes} >= {'sim', 'fsm', 'classifier'}
    model = 'package://mindgrasp_classifier/models/default_classifier.json'   # package data
    plan = LaunchService('demo', [f'model:={model}']).plan(strict=True)
    classifier = next(p for p in plan.processes if p.label == 'classifier')
    assert classifier.parameters['model'] == model
