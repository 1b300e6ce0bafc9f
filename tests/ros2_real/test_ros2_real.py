"""A real ROS 2 Jazzy on the other side: the real ``ros2`` CLI against our runtime's nodes, our
``mindgrasp`` verbs against real rclpy nodes, and our nodes on the real rclpy
(``MINDGRASP_RMW=rclpy``). Every process is a separate one; the wire is Cyclone DDS."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

pytestmark = [pytest.mark.slow, pytest.mark.ros2_real]

PEER = str(Path(__file__).resolve().parents[1] / 'ros' / 'ros_peer.py')


def mindgrasp(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args], env=env,
                          capture_output=True, text=True, timeout=120, check=False)


def until(run, ok, timeout: float = 60.0):
    """Run ``run()`` until ``ok(result)`` (discovery takes its time); the last result."""
    deadline = time.monotonic() + timeout
    while True:
        result = run()
        if ok(result) or time.monotonic() > deadline:
            return result
        time.sleep(1.0)


def test_real_ros2_cli_against_our_sim_node(spawn_node, ros2):
    sim = spawn_node('mindgrasp_sim.sim_node', duration=300.0, camera_rate=1.0)
    assert sim.wait_for_output('Simulating scene', 120), sim.output()
    nodes = until(lambda: ros2('node', 'list', '--no-daemon'),
                  lambda r: '/sim' in r.stdout.split())
    assert '/sim' in nodes.stdout.split(), nodes.stdout + nodes.stderr
    call = ros2('service', 'call', '/sim/reset', 'mindgrasp_msgs/srv/ResetSim', '{seed: 3}')
    assert call.returncode == 0 and 'success=True' in call.stdout, call.stdout + call.stderr
    def param(*args: str) -> subprocess.CompletedProcess:
        return ros2('param', *args, '--no-daemon')     # no daemon outlives the test

    assert param('get', '/sim', 'camera_rate').stdout.strip() == 'Double value is: 1.0'
    assert param('set', '/sim', 'use_sim_time', 'false').stdout.strip() == \
        'Set parameter successful'
    assert param('get', '/sim', 'use_sim_time').stdout.strip() == 'Boolean value is: False'
    refused = param('set', '/sim', 'camera_rate', '2.0')      # read-only: refused
    assert "Setting parameter failed: parameter 'camera_rate' is read-only" in refused.stderr
    echo = ros2('topic', 'echo', '--once', '--no-daemon', '/joint_states',
                'sensor_msgs/msg/JointState')
    assert 'name:\n- joint_1' in echo.stdout, echo.stdout + echo.stderr
    # our verbs print what ros2's print
    ours = mindgrasp('service', 'list', '-t').stdout
    theirs = ros2('service', 'list', '-t', '--no-daemon').stdout
    assert ours == theirs
    # common types are shown without comments and defaults (we have no .msg file of them)
    for args in (('show', 'mindgrasp_msgs/srv/ResetSim'),
                 ('show', 'mindgrasp_msgs/msg/MIPrediction'),
                 ('show', 'geometry_msgs/msg/Point', '--no-comments'),
                 ('proto', 'mindgrasp_msgs/srv/ResetSim'),
                 ('proto', 'geometry_msgs/msg/Quaternion')):
        assert mindgrasp('interface', *args).stdout == ros2('interface', *args).stdout, args


def test_our_verbs_against_a_real_rclpy_node(spawn_node, rclpy_env, tmp_path):
    peer = spawn_node(PEER, 'params', env=rclpy_env)
    assert peer.wait_for_output('ready', 60), peer.output()
    got = until(lambda: mindgrasp('param', 'get', '/peer_params', 'gain'),
                lambda r: r.returncode == 0)
    assert got.stdout.strip() == 'Double value is: 1.0', got.stderr
    # rclpy refuses an integer for a double parameter (our runtime converts it)
    wrong = mindgrasp('param', 'set', '/peer_params', 'gain', '5')
    assert wrong.returncode == 1 and "expected 'Type.DOUBLE' got 'Type.INTEGER'" in wrong.stderr
    assert mindgrasp('param', 'set', '/peer_params', 'gain', '5.0').returncode == 0
    dumped = mindgrasp('param', 'dump', '/peer_params', '--output-dir', str(tmp_path))
    assert dumped.returncode == 0, dumped.stderr
    data = yaml.safe_load((tmp_path / 'peer_params.yaml').read_text())
    params = data['/peer_params']['ros__parameters']
    assert params['gain'] == 5.0 and params['nested'] == {'level': 0}
    params['gain'] = 7.5
    (tmp_path / 'peer_params.yaml').write_text(yaml.safe_dump(data))
    loaded = mindgrasp('param', 'load', '/peer_params', str(tmp_path / 'peer_params.yaml'))
    assert 'Set parameter gain successful' in loaded.stdout, loaded.stdout + loaded.stderr
    listing = mindgrasp('service', 'list', '-t').stdout.splitlines()
    assert '/toggle [std_srvs/srv/SetBool]' in listing
    call = mindgrasp('service', 'call', '/toggle', 'std_srvs/srv/SetBool', '{data: true}')
    assert "message='on=True gain=7.5'" in call.stdout, call.stdout + call.stderr


def test_our_topic_verbs_against_a_real_rclpy_talker(spawn_node, rclpy_env, ros2):
    talker = spawn_node(PEER, 'talker', env=rclpy_env)
    listed = until(lambda: mindgrasp('topic', 'list', '-t'),
                   lambda r: '/chatter [std_msgs/msg/String]' in r.stdout.splitlines())
    assert '/chatter [std_msgs/msg/String]' in listed.stdout.splitlines(), \
        listed.stdout + listed.stderr + talker.output()
    echo = mindgrasp('topic', 'echo', '--once', '/chatter')
    assert echo.returncode == 0 and echo.stdout.startswith('data:') and 'hello ' in echo.stdout, \
        echo.stdout + echo.stderr
    # the same lines as the real ros2 topic info
    theirs = until(lambda: ros2('topic', 'info', '/chatter', '--no-daemon'),
                   lambda r: 'Publisher count: 1' in r.stdout)
    assert mindgrasp('topic', 'info', '/chatter').stdout == theirs.stdout


def test_our_controller_on_real_rclpy(spawn_node, rclpy_env, ros2):
    fsm = spawn_node('mindgrasp_fsm.fsm_node', env=rclpy_env)
    assert fsm.wait_for_output('Grasp controller ready', 60), fsm.output()
    described = until(lambda: ros2('param', 'describe', '/fsm', 'lock_duration', '--no-daemon'),
                      lambda r: r.returncode == 0 and 'Min value' in r.stdout)
    assert 'Min value: 0.001' in described.stdout, described.stdout + described.stderr
    assert ros2('param', 'set', '/fsm', 'lock_duration', '2.5', '--no-daemon').stdout.strip() == \
        'Set parameter successful'
    refused = ros2('param', 'set', '/fsm', 'lock_duration', '-1.0', '--no-daemon')
    assert 'Setting parameter failed' in refused.stdout + refused.stderr
    assert mindgrasp('param', 'get', '/fsm', 'lock_duration').stdout.strip() == \
        'Double value is: 2.5'


def test_a_recorded_launch_on_real_rclpy(rclpy_env, tmp_path):
    """`MINDGRASP_RMW=rclpy mindgrasp launch sim`: the recorder and the simulator on the real
    rclpy (both died at start before: params.py), served and recorded as on our runtime."""
    run = tmp_path / 'run'
    proc = subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'launch', 'sim',
                             'duration:=300', '--run-dir', str(run)], env=rclpy_env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    changes = run / 'params' / 'changes.jsonl'
    try:
        call = until(lambda: mindgrasp('service', 'call', '/sim/reset',
                                       'mindgrasp_msgs/srv/ResetSim', '{seed: 2}'),
                     lambda r: r.returncode == 0, 120)
        assert 'ResetSim_Response(success=True' in call.stdout, call.stdout + call.stderr
        assert mindgrasp('param', 'set', '/sim', 'use_sim_time', 'false').returncode == 0
        assert until(lambda: changes.read_text(), lambda text: '"/sim"' in text, 60)
    finally:
        proc.send_signal(2)   # SIGINT, as Ctrl-C
        out = proc.communicate(timeout=180)[0]
    assert proc.returncode == 130, out[-3000:]      # interrupted by SIGINT, every process clean
    assert 'every process stopped cleanly' in out, out[-3000:]
    row = [r for r in map(yaml.safe_load, changes.read_text().splitlines()) if r['node'] == '/sim']
    assert (row[0]['name'], row[0]['old'], row[0]['new']) == ('use_sim_time', False, False)
