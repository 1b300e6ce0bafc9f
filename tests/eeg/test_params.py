"""The EEG nodes' parameters: the parameter file and the dataclasses agree; a bad value is refused
at start with one line (exit code 2); a failure while running is exit code 1 with one line."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from mindgrasp_eeg.params import AcquisitionParams, VirtualAmpParams
from mindgrasp_ros.params import ParameterError, describe, from_mapping

NODES = [('eeg_acquisition', AcquisitionParams), ('virtual_amp', VirtualAmpParams)]


# the parameter file against the defaults: tests/ros/test_node_params.py, with every node


@pytest.mark.parametrize(('node_name', 'cls'), NODES)
def test_every_parameter_is_described_and_read_only(node_name: str, cls: type) -> None:
    for name, (_, desc) in describe(cls).items():
        assert desc.description and desc.read_only, name


@pytest.mark.parametrize(('cls', 'values', 'match'), [
    (AcquisitionParams, {'sample_rate': -1.0}, r"'sample_rate' must be within \[0, inf\] Hz"),
    (AcquisitionParams, {'nan_policy': 'zero'}, r"'nan_policy' is 'zero'; use one of replace"),
    (AcquisitionParams, {'chunk_period': 0.0}, r"'chunk_period' must be within"),
    (VirtualAmpParams, {'output': 'udp'}, r"'output' is 'udp'; use one of lsl, ros"),
    (VirtualAmpParams, {'accuracy': 1.5}, r"'accuracy' must be within \[0, 1\]"),
    (VirtualAmpParams, {'subject_mode': 'chase'}, r"'subject_mode' is 'chase'; use one of noise"),
    (VirtualAmpParams, {'sample_rate': 30.0}, r"'sample_rate' must be within \[60, "),
])
def test_bad_values_name_the_parameter(cls: type, values: dict, match: str) -> None:
    with pytest.raises(ParameterError, match=match):
        from_mapping(cls, values)


def _run(module: str, *params: str) -> subprocess.CompletedProcess:
    args = [a for p in params for a in ('-p', p)]
    env = {**os.environ, 'PYTHONUNBUFFERED': '1'}
    return subprocess.run([sys.executable, '-m', module, '--ros-args', *args], env=env,
                          capture_output=True, text=True, timeout=120, check=False)


def _error_lines(run: subprocess.CompletedProcess) -> list[str]:
    return [line for line in (run.stdout + run.stderr).splitlines() if 'ERROR' in line]


@pytest.mark.parametrize(('module', 'param', 'words'), [
    ('mindgrasp_eeg.acquisition_node', 'sample_rate:=-1',
     ('[AcquisitionNode] ERROR:', "'sample_rate'", '-1', '[0.0, inf]')),
    ('mindgrasp_eeg.virtual_amp_node', 'sample_rate:=-1',
     ('[VirtualAmpNode] ERROR:', "'sample_rate'", '-1', '[60.0, 100000.0]')),
    ('mindgrasp_eeg.virtual_amp_node', 'subject_mode:=chase',
     ('[VirtualAmpNode] ERROR:', "'subject_mode' is 'chase'; use one of noise, follow, pursue")),
    ('mindgrasp_eeg.virtual_amp_node', 'eeg_source:=missing/subject.yaml',
     ('[VirtualAmpNode] ERROR:', "The subject file '", "missing/subject.yaml' does not exist")),
])
def test_a_bad_parameter_ends_the_node_process_with_exit_code_2_and_one_line(
        module: str, param: str, words: tuple[str, ...]) -> None:
    run = _run(module, param)
    assert run.returncode == 2, run.stdout + run.stderr
    assert 'Traceback' not in run.stderr
    lines = _error_lines(run)
    assert len(lines) == 1, run.stdout + run.stderr
    assert lines[0].startswith(words[0]) and all(w in lines[0] for w in words[1:]), lines[0]


def test_a_bad_stream_selector_is_refused_with_exit_code_2() -> None:
    """A parameter the EEG package checks itself (not a range): still a refusal to start."""
    run = _run('mindgrasp_eeg.acquisition_node', 'stream_unit:=furlongs')
    assert run.returncode == 2, run.stdout + run.stderr
    lines = _error_lines(run)
    assert len(lines) == 1 and "The EEG unit 'furlongs' is unknown" in lines[0], run.stderr


def test_a_stream_not_found_while_running_is_exit_code_1_with_the_reason(stream_name) -> None:
    run = _run('mindgrasp_eeg.acquisition_node', f'stream_name:={stream_name}',
               'resolve_timeout:=0.5')
    assert run.returncode == 1, run.stdout + run.stderr
    assert 'Traceback' not in run.stderr
    assert f"[eeg_acquisition] ERROR: No LSL stream with name='{stream_name}'" in run.stderr


def test_a_running_virtual_amp_shows_its_descriptors_and_refuses_a_change() -> None:
    """In a node (lock-step, in this process): the declared ranges and units are the
    ParameterDescriptors; a change while it runs is refused with the reason."""
    from mindgrasp_eeg.virtual_amp_node import VirtualAmpNode
    from mindgrasp_ros import rclpy
    from mindgrasp_ros.graph.lockstep import LockstepRunner

    with LockstepRunner(start_time_s=1.0) as runner:
        node = runner.add(VirtualAmpNode, ros_args=['-p', 'output:=ros', '-p', 'accuracy:=0.7'])
        assert node.params.accuracy == 0.7
        desc = node.describe_parameter('sample_rate')
        assert desc.read_only and '[Hz]' in desc.description
        assert desc.floating_point_range[0].from_value == 60.0
        assert 'one of: noise, follow, pursue' in \
            node.describe_parameter('subject_mode').additional_constraints
        result = node.set_parameters([rclpy.parameter.Parameter('accuracy', value=0.5)])[0]
        assert not result.successful and 'read-only' in result.reason
        assert node.params.accuracy == 0.7
