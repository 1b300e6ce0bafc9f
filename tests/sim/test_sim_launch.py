"""The ``sim`` launch profile: what it starts, resolved without starting anything, and a short
real launch that records the simulator's topics."""

from __future__ import annotations

import os
import time

import pytest

from mindgrasp_launch import LaunchService
from mindgrasp_ros.node_process import NodeProcess


def sim_process(*args: str):
    plan = LaunchService('sim', list(args)).plan(strict=True)
    procs = {spec.label: spec for spec in plan.processes}
    return procs['sim']


def test_sim_profile_defaults_follow_the_parameter_file():
    sim = sim_process('record:=false')
    assert sim.module == 'mindgrasp_sim.sim_node'
    p = sim.parameters
    assert (p['camera_width'], p['camera_height'], p['camera_rate']) == (128, 128, 10.0)
    assert p['scene'] == 'set_locations' and p['time_mode'] == 'realtime'
    assert p['physics_hz'] == 240.0 and p['command_timeout'] == 0.25
    assert p['trainer_robot'] is False and p['gui'] is False


def test_sim_profile_arguments():
    p = sim_process('record:=false', 'camera:=640x480@30', 'scene:=random_locations', 'seed:=7',
                    'time_mode:=fast', 'trainer_robot:=true').parameters
    assert (p['camera_width'], p['camera_height'], p['camera_rate']) == (640, 480, 30.0)
    assert p['scene'] == 'random_locations' and p['seed'] == 7
    assert p['time_mode'] == 'fast' and p['trainer_robot'] is True


@pytest.mark.slow
def test_sim_launch_runs_and_records(tmp_path):
    """A real launch, stopped with Ctrl-C once the recorder has subscribed to the simulator's
    topics (however long a loaded host takes to start the simulator: a fixed duration:=6 ended
    one launch before the simulator had imported PyBullet)."""
    run_dir = tmp_path / 'run'
    topics = ('/joint_states', '/camera/color/image_raw', '/camera/depth/image_raw',
              '/camera/color/camera_info', '/ee_pose', '/sim/objects', '/clock')
    launch = NodeProcess('mindgrasp_cli', ['launch', 'sim', 'time_mode:=fast', '--run-dir',
                                               str(run_dir)],
                         dict(os.environ), tmp_path / 'launch.log')
    try:
        log = run_dir / 'logs' / 'recorder.log'
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and launch.poll() is None and not (
                log.is_file() and all(f'Subscribed to {t} ' in log.read_text() for t in topics)):
            time.sleep(0.2)
        subscribed = log.read_text() if log.is_file() else ''
    finally:
        code = launch.stop(timeout=30)
    assert all(f'Subscribed to {t} ' in subscribed for t in topics), launch.output()
    assert code == 130, launch.output()     # stopped by Ctrl-C: interrupted, every process clean
    metadata = (run_dir / 'bag' / 'metadata.yaml').read_text()
    for topic in topics:
        assert f'name: {topic}\n' in metadata, topic


@pytest.mark.parametrize('text', [
    "1'.split('x')[0]) or __import__('os').system('touch /tmp/pwned') or int('1",
    '{0.__class__.__mro__}x1@1',
    '640x480',
    '640x480@',
    'x480@30',
    '640 x 480 @ 30; rm -rf /',
    '0x480@30',
    '640x480@1e3',
])
def test_camera_argument_is_parsed_never_evaluated(text):
    """Hostile or malformed camera:= text: one clear error naming the form, nothing run."""
    from mindgrasp_launch import LaunchError

    with pytest.raises(LaunchError, match=r'camera:=.* e\.g\. camera:=640x480@30'):
        sim_process('record:=false', f'camera:={text}')


def test_parse_camera():
    from mindgrasp_launch.launch_args import parse_camera

    assert parse_camera('640x480@30') == (640, 480, 30.0)
    assert parse_camera(' 128x96@7.5 ') == (128, 96, 7.5)
    with pytest.raises(ValueError, match='is not WIDTHxHEIGHT@HZ'):
        parse_camera('640x480')
