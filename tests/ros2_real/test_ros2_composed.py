"""A composed graph on the real rclpy: the graph host builds each node with rclpy's own
``Node(cli_args=..., parameter_overrides=...)``, so a spec's name, remaps and typed parameters
reach the node whichever rclpy runs it (issue 41; our runtime's side: tests/ros/test_graph_hosts).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.ros2_real

FIXTURES = Path(__file__).resolve().parents[1] / 'bringup'

#: run in a process of its own with MINDGRASP_RMW=rclpy; prints one JSON line
SCRIPT = '''
import json, sys
from mindgrasp_ros import rclpy
from mindgrasp_ros.graph import GraphRunner, InProcess, NodeSpec

assert rclpy.__name__ == 'rclpy', rclpy.__name__          # the real one
remaps = {'chatter': '/composed/chatter'}
talker_spec = NodeSpec('talker', 'launch_fixtures.talker', name='speaker', remaps=remaps,
                       parameters={'count': 10000, 'period': 0.05, 'prefix': 'composed'})
listener_spec = NodeSpec('listener', 'launch_fixtures.listener', remaps=remaps,
                         parameters={'expect': 5, 'prefix': 'composed', 'timeout': 90.0})
with GraphRunner(InProcess()) as runner:
    talker = runner.add(talker_spec)
    listener = runner.add(listener_spec)
    runner.spin_until(lambda: listener.heard >= 5, limit_s=90.0)
    print(json.dumps({
        'talker_name': talker.get_fully_qualified_name(),
        'publisher_topic': talker.publisher.topic_name,
        'subscription_topics': [s.topic_name for s in listener.subscriptions],
        'count': talker.get_parameter('count').value,
        'period': talker.get_parameter('period').value,
        'prefix': listener.get_parameter('prefix').value,
        'timeout': listener.get_parameter('timeout').value,
        'heard': listener.heard,
    }))
'''


def test_a_composed_graph_keeps_its_remaps_and_parameters_on_real_rclpy(rclpy_env, tmp_path):
    env = dict(rclpy_env)
    env['PYTHONPATH'] = os.pathsep.join(p for p in (str(FIXTURES), env.get('PYTHONPATH')) if p)
    script = tmp_path / 'composed.py'
    script.write_text(SCRIPT, encoding='utf-8')
    run = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True,
                         timeout=180, check=False)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-3000:]
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert got['talker_name'] == '/speaker'                               # -r __node:=speaker
    assert got['publisher_topic'] == '/composed/chatter'                  # -r chatter:=...
    assert '/composed/chatter' in got['subscription_topics']
    # typed parameter_overrides: int stays int, float float, over the nodes' defaults
    assert (got['count'], got['period'], got['prefix'], got['timeout']) == \
        (10000, 0.05, 'composed', 90.0)
    assert got['heard'] >= 5
