"""The recorder, player and replay nodes' declared parameters: descriptors, what the launch
profiles pass, and a bad parameter refusing to start (exit 2, one line) in a real process.

None of the three has a parameter file of its own (their parameters come from the launch profile
or the ``mindgrasp bag``/``replay`` commands), so there is no YAML to compare the defaults with;
the launch profile's parameters are checked against the dataclasses instead.
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys

import pytest

from mindgrasp_bag.player_node import PlayerParams
from mindgrasp_bag.recorder_node import RecorderParams
from mindgrasp_bringup.replay.replay_node import ReplayParams
from mindgrasp_launch import LaunchService
from mindgrasp_ros.params import ParameterError, describe, from_mapping

PARAMS = {'mindgrasp_bag.recorder_node': RecorderParams,
          'mindgrasp_bag.player_node': PlayerParams,
          'mindgrasp_bringup.replay.replay_node': ReplayParams}


@pytest.mark.parametrize('cls', PARAMS.values(), ids=lambda c: c.__name__)
def test_every_parameter_is_described_and_read_only(cls) -> None:
    for name, (_default, desc) in describe(cls).items():
        assert desc.description and desc.read_only, name
    assert from_mapping(cls, {}) == cls()     # the defaults pass their own checks


def test_launch_profiles_pass_only_declared_parameters(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    plan = LaunchService('replay', ['bag:=/data/run', 'record_topics:=/a /b',
                                    'record_regex:=^/eeg']).plan(strict=False)
    modules = {spec.module: spec for spec in plan.processes}
    for module, cls in PARAMS.items():
        if module in modules:
            names = {f.name for f in dataclasses.fields(cls)}
            assert set(modules[module].parameters) <= names, module
    assert {'mindgrasp_bag.recorder_node', 'mindgrasp_bringup.replay.replay_node'} \
        <= set(modules)
    recorder = modules['mindgrasp_bag.recorder_node'].parameters
    assert from_mapping(RecorderParams, recorder).topics == ['/a', '/b']


def test_dataclass_checks_name_the_parameter() -> None:
    with pytest.raises(ParameterError, match='fix the exclude_regex parameter'):
        RecorderParams(exclude_regex='[')
    with pytest.raises(ParameterError, match=r"'rate' must be > 0 \(1.0 = real time\)"):
        PlayerParams(rate=0.0)


@pytest.mark.parametrize(('module', 'params', 'match'), [
    ('mindgrasp_bag.recorder_node', ['regex:=(', 'output:={tmp}/bag'],
     'The topic regular expression is not valid'),
    ('mindgrasp_bag.recorder_node', ['compression:=bz2', 'output:={tmp}/bag'],
     "The parameter 'compression' is 'bz2'; use one of none, zstd, lz4."),
    ('mindgrasp_bag.recorder_node', ['max_queue_mb:=0', 'output:={tmp}/bag'],
     "'max_queue_mb'"),
    ('mindgrasp_bag.recorder_node', ['custom_data:=["robot"]', 'output:={tmp}/bag'],
     "custom_data entry 'robot' is not KEY=VALUE"),
    ('mindgrasp_bag.player_node', [], 'The parameter bag is empty'),
    ('mindgrasp_bag.player_node', ['bag:={tmp}/nope'],
     'nope does not exist; pass a run directory'),
    ('mindgrasp_bag.player_node', ['bag:={tmp}', 'rate:=0.0'], "'rate' must be > 0"),
    ('mindgrasp_bringup.replay.replay_node', [], 'No bag given'),
    ('mindgrasp_bringup.replay.replay_node', ['bag:={tmp}/nope'],
     'nope does not exist; pass a run directory'),
    ('mindgrasp_bringup.replay.replay_node', ['bag:={tmp}/nope', 'robot:=ur5'],
     "No robot is named 'ur5'; use one of"),
], ids=['recorder-regex', 'recorder-compression', 'recorder-queue', 'recorder-custom-data',
        'player-no-bag',
        'player-missing-bag', 'player-rate', 'replay-no-bag', 'replay-missing-bag',
        'replay-robot'])
def test_bad_parameter_refuses_to_start_with_exit_2_and_one_line(tmp_path, module, params, match):
    args = [a.format(tmp=tmp_path) for a in params]
    ros_args = ['--ros-args', *[x for a in args for x in ('-p', a)]] if args else []
    out = subprocess.run([sys.executable, '-m', module, *ros_args], capture_output=True,
                         text=True, timeout=120)
    lines = out.stderr.strip().splitlines()
    assert out.returncode == 2, out.stdout + out.stderr
    assert len(lines) == 1 and match in lines[0] and 'ERROR' in lines[0], out.stderr
    assert not (tmp_path / 'bag').exists()    # a refused recorder creates nothing
