"""``mindgrasp run <package> <executable>``: a node by its ROS package and executable name, as
``ros2 run`` starts it."""

from __future__ import annotations

import subprocess
import sys

import pytest

GRAZ_FAST = ['--ros-args', '-p', 'n_trials:=1', '-p', 'start_delay:=0.2', '-p', 'fixation:=0.2',
             '-p', 'cue:=0.2', '-p', 'imagery:=0.2', '-p', 'rest_min:=0.1', '-p', 'rest_max:=0.1',
             '-p', 'display_rate:=0.0']


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'run', *args],
                          capture_output=True, text=True, timeout=120, check=False)


@pytest.mark.slow
def test_runs_a_node_with_its_ros_arguments_to_its_end() -> None:
    done = _run('mindgrasp_trainer', 'graz_node', *GRAZ_FAST)
    assert done.returncode == 0, done.stderr
    assert 'Graz-BCI session: 1 trials' in done.stdout + done.stderr


def test_unknown_executable_exits_2_naming_the_module() -> None:
    done = _run('mindgrasp_fsm', 'no_such_node')
    assert done.returncode == 2
    assert "the node module 'mindgrasp_fsm.no_such_node' does not exist" in done.stderr
    assert 'Traceback' not in done.stderr
