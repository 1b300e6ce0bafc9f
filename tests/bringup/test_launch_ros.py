"""The launcher with ROS 2 nodes of the client layer (talker and listener fixtures over real
DDS): topics flow, parameters and remappings arrive, the recorder writes the run's bag, SIGTERM
stops the nodes cleanly, and ``--composed`` runs them in one process."""

from __future__ import annotations

import re
import signal
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import (
    fixture,
    kill_group,
    run_launch,
    start_launch,
    wait_for_file_text,
)

pytestmark = pytest.mark.slow


def test_topics_flow_between_launched_nodes_and_are_recorded(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    result = run_launch(fixture('talk.launch.py'), 'prefix:=bonjour', 'count:=60',
                        '--run-dir', str(run_dir), timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    listener_log = (run_dir / 'logs' / 'listener.log').read_text()
    # the parameter (--params-file), namespace and remapping all reached the nodes
    assert len(re.findall(r'\[demo\.listener\]: I heard: "bonjour \d+"', listener_log)) >= 5
    assert '[demo.talker]: Publishing: "bonjour 0"' in (run_dir / 'logs' / 'talker.log').read_text()
    summary = yaml.safe_load((run_dir / 'summary.yaml').read_text())
    assert [(p['label'], p['how'], p['clean']) for p in summary['processes']] == [
        ('recorder', 'stopped by SIGINT', True), ('talker', 'finished', True),
        ('listener', 'finished', True)]
    # the recorder started first, stopped last and wrote the bag into the run directory
    from mindgrasp_bag.reader import BagReader

    with BagReader(run_dir / 'bag') as reader:
        reader.open()
        assert '/demo/conversation' in reader.topics
        messages = list(reader.messages(['/demo/conversation']))
    assert len(messages) >= 5
    assert b'bonjour' in messages[0][2]


def test_sigterm_stops_ros_nodes_cleanly(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    proc = start_launch(fixture('talk.launch.py'), 'count:=100000', 'expect:=100000',
                        'record:=false', '--run-dir', str(run_dir))
    try:
        assert wait_for_file_text(run_dir / 'logs' / 'listener.log', 'I heard', timeout=60)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        kill_group(proc)
    assert proc.returncode == 128 + signal.SIGTERM, err[-3000:]   # 143: interrupted, cleanly
    assert re.findall(r'process has finished cleanly \[pid \d+\]: (\w+)', err) == [
        'listener', 'talker']


def test_composed_runs_the_nodes_in_one_process(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    result = run_launch(fixture('talk.launch.py'), '--composed', 'duration:=5', 'record:=false',
                        '--run-dir', str(run_dir), timeout=120)
    assert result.returncode == 0, result.stderr[-3000:]
    assert 'composing 2 node(s) in one process: talker, listener' in result.stderr
    log = (run_dir / 'logs' / 'composed.log').read_text()
    assert 'Publishing: "greetings' in log and 'I heard: "greetings' in log
    # output is prefixed by the node, and split into per-node logs
    assert re.search(r'^\[listener\] \[INFO\] .*I heard: "greetings', result.stdout + result.stderr,
                     re.MULTILINE)
    assert 'I heard' in (run_dir / 'logs' / 'listener.log').read_text()
    assert 'I heard' not in (run_dir / 'logs' / 'talker.log').read_text()
    pids = re.findall(r'process started with pid \[(\d+)\]', result.stderr)
    assert len(pids) == 1
    components = yaml.safe_load((run_dir / 'composed.yaml').read_text())['components']
    assert [c['node'] for c in components] == ['/demo/talker', '/demo/listener']
    assert '--params-file' in components[0]['ros_args']
