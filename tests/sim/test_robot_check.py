"""``mindgrasp robot check``: a shipped pair passes; a broken description (a wrong joint name, a
TCP inside the palm, a camera looking away) is named in one FIX line, exit 1. The command runs
as users run it, in its own process."""

from __future__ import annotations

import math
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from mindgrasp_common.resources import resource_path

pytestmark = pytest.mark.slow


def _check(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'robot', 'check', *args],
                          capture_output=True, text=True, timeout=1400, cwd=cwd, check=False)


def _robot(tmp_path: Path, edit) -> Path:
    """The xArm6 with a copy of its gripper's description, ``edit(hand)`` applied."""
    hand = yaml.safe_load(resource_path('mindgrasp_sim', 'robots', 'hands',
                                        'xarm_gripper.yaml').read_text(encoding='utf-8'))
    hand['urdf'] = str(resource_path('mindgrasp_sim', 'urdf', 'xarm_gripper.urdf'))
    edit(hand)
    (tmp_path / 'hand.yaml').write_text(yaml.safe_dump(hand), encoding='utf-8')
    path = tmp_path / 'robot.yaml'
    path.write_text(yaml.safe_dump({'name': 'mine', 'arm': 'xarm6', 'hand': 'hand.yaml',
                                    'mount': {'joint': 'gripper_fix'}}), encoding='utf-8')
    return path


def test_a_shipped_pair_passes(tmp_path):
    run = _check('xarm6', '--grasps', '0', '--out', str(tmp_path / 'out'), cwd=tmp_path)
    assert run.returncode == 0, run.stdout + run.stderr
    assert 'FIX' not in run.stdout and 'xarm6: every check passed' in run.stdout
    assert 'drive_joint' in run.stdout and 'joint6' in run.stdout      # the joint table
    for file in ('camera.png', 'reachability.png', 'reachability.csv'):
        assert (tmp_path / 'out' / file).stat().st_size > 0


def _wrong_joint(hand):
    hand['joints'] = ['drive_joint', 'left_finger']


def _tcp_in_palm(hand):
    hand['tcp']['xyz'] = [0.0, 0.0, 0.03]


def _camera_away(hand):
    hand['camera']['rpy'] = [math.pi, 0.0, 0.0]


@pytest.mark.parametrize(('edit', 'fault'), [
    (_wrong_joint, r"FIX Hand description '.*hand.yaml': the gripper joints name the joint "
                   r"'left_finger', which the URDF xarm_gripper.urdf lacks"),
    (_tcp_in_palm, r"FIX the TCP is inside the link 'xarm_gripper_base_link' \(\d+ mm deep with "
                   r'the hand open\); move tcp: xyz'),
    (_camera_away, r'FIX the camera looks away from the objects: .*; turn camera: rpy'),
])
def test_a_broken_description_is_named_in_one_line(tmp_path, edit, fault):
    run = _check(str(_robot(tmp_path, edit)), '--grasps', '0', '--out', str(tmp_path / 'out'),
                 cwd=tmp_path)
    assert run.returncode == 1, run.stdout + run.stderr
    fixes = [line for line in run.stdout.splitlines() if line.startswith('FIX')]
    assert len(fixes) == 1, run.stdout
    assert re.fullmatch(fault + ".*", fixes[0]), fixes[0]


@pytest.mark.timeout(1500)     # a lock-step trial, the map and the checks: minutes when loaded
def test_grasps_in_lockstep(tmp_path):
    run = _check('mindgrasp_arm', '--grasps', '1', '--realism', 'none', '--out',
                 str(tmp_path / 'out'), cwd=tmp_path)
    assert 'autonomous grasps (random locations, seed 0, realism none): ' in run.stdout, \
        run.stdout + run.stderr
    assert 'CPU s per simulated s' in run.stdout
    assert (tmp_path / 'out' / 'grasps' / 'records.csv').is_file()
