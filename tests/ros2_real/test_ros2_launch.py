"""``ros2 launch mindgrasp_bringup demo.launch.py`` from a colcon workspace of our packages: the
real launch and launch_ros start our nodes, each on the real rclpy (``MINDGRASP_RMW=rclpy``),
and the arm grasps the object the trial asks for (issue 32)."""

from __future__ import annotations

import csv
import os
import signal
import subprocess
import uuid
from pathlib import Path

import pytest
import yaml

pytestmark = [pytest.mark.slow, pytest.mark.ros2_real]

#: every process of the demo profile without a display and the live view
DEMO_NODES = {'recorder_node', 'trial_manager_node', 'sim_node', 'virtual_amp_node',
              'acquisition_node', 'classifier_node', 'vision_node', 'fsm_node'}


def test_ros2_launch_demo_grasps_on_real_rclpy(colcon_ws, tmp_path: Path) -> None:
    from mindgrasp_bringup.bag.reader import BagReader
    from mindgrasp_bringup.bag.typestore import typestore

    run = tmp_path / 'run'
    proc = subprocess.Popen(
        ['ros2', 'launch', 'mindgrasp_bringup', 'demo.launch.py', 'trials:=1',
         'targets:=red cube', 'live_view:=false', f'eeg_stream:=mg-ros2-{uuid.uuid4().hex[:8]}',
         f'run_dir:={run}'], env=colcon_ws, stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        # the demo ends by itself when its trial is done (about 45 s here)
        out = proc.communicate(timeout=300)[0]
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
            out = proc.communicate(timeout=60)[0]
    assert proc.returncode == 0, out[-4000:]
    assert 'Traceback' not in out, out[-4000:]
    summary = yaml.safe_load((run / 'summary.yaml').read_text())
    assert summary['stop_reason'] == 'the trials are done', summary
    ended = {p['label'].rsplit('-', 1)[0]: p for p in summary['processes']}
    assert set(ended) == DEMO_NODES, sorted(ended)
    assert all(p['clean'] and p['returncode'] == 0 for p in ended.values()), summary
    # the trial's record and the recorded result: the red cube grasped
    with (run / 'trials' / 'records.csv').open(encoding='utf-8') as f:
        (record,) = csv.DictReader(f)
    assert (record['desired'], record['grasped'], record['outcome']) == \
        ('red cube', 'red cube', 'correct_grasp'), record
    store = typestore()
    with BagReader(run / 'bag') as bag:
        results = [store.deserialize_cdr(data, 'mindgrasp_msgs/msg/GraspResult')
                   for _topic, _t, data in bag.messages(['/task/result'])]
    assert [(r.desired_object, r.grasped_object, r.success) for r in results] == \
        [('red cube', 'red cube', True)], results
