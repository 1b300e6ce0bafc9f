"""A Trainer session on another robot: ``mindgrasp launch trainer robot:=xarm6`` (or
``robot:=panda``) runs the user's arm and the training robot as two xArm6s (two seven-joint
Pandas: the trainer's command has seven velocities), one description read by the simulator, the
controller and the trainer, each in its own process over real DDS, end to end until the trainer
ends the launch."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from mindgrasp_common.robot_description import load_robot

pytestmark = pytest.mark.slow


@pytest.mark.timeout(600)
@pytest.mark.parametrize('robot', ['xarm6', 'panda'])
def test_a_trainer_session_runs_on_two_copies_of_the_robot(robot: str, tmp_path: Path) -> None:
    from mindgrasp_bag import BagReader
    from mindgrasp_ros.typesupport import typestore

    arm = load_robot(robot)
    run_dir = tmp_path / 'run'
    env = {**os.environ, 'ROS_DOMAIN_ID': os.environ.get('ROS_DOMAIN_ID', '43')}
    result = subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'trainer', f'robot:={robot}',
         'trials:=2', 'seed:=2', '--run-dir', str(run_dir)],
        capture_output=True, text=True, timeout=540, check=False, env=env)
    output = result.stdout[-4000:] + result.stderr[-4000:]
    assert result.returncode == 0, output
    logs = run_dir / 'logs'
    assert f"with the robot '{robot}'" in (logs / 'sim.log').read_text(), output
    trainer_log = (logs / 'trainer.log').read_text()
    assert 'Trial 2: end-effector distance' in trainer_log, trainer_log
    assert '"n_trials": 2, "n_aborted": 0' in trainer_log, trainer_log
    # every node that reads the robot was given the same one
    params = yaml.safe_load((run_dir / 'params.yaml').read_text())
    for node in ('sim', 'fsm', 'trainer'):
        section = params.get(f'/{node}', params.get(node))
        assert section['ros__parameters']['robot'] == robot, node
    # the bag says which robot it holds, for a reader that has the bag folder only
    metadata = yaml.safe_load((run_dir / 'bag' / 'metadata.yaml').read_text())
    assert metadata['rosbag2_bagfile_information']['custom_data']['robot'] == robot
    store = typestore()
    with BagReader(run_dir / 'bag') as reader:
        states = [store.deserialize_cdr(data, 'sensor_msgs/msg/JointState')
                  for _t, _s, data in reader.messages(['/trainer_robot/joint_states'])]
        commands = [store.deserialize_cdr(data, 'std_msgs/msg/Float64MultiArray')
                    for _t, _s, data in reader.messages(
                        ['/trainer_robot/arm_controller/commands'])]
        description = [store.deserialize_cdr(data, 'std_msgs/msg/String').data
                       for _t, _s, data in reader.messages(['/robot_description'])]
    # the training robot is a second copy of the arm: its joints, one velocity per joint
    assert states and all(list(s.name) == list(arm.arm_joints) for s in states)
    assert commands and all(len(c.data) == len(arm.arm_joints) for c in commands)
    moving = [c for c in commands if any(abs(v) > 0 for v in c.data)]
    assert moving, 'the training robot never moved'
    assert description and all(f'<joint name="{j}"' in description[0] for j in arm.arm_joints)
