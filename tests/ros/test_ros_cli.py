"""`mindgrasp topic|node|param` against a running graph in other processes."""

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

PEER = str(Path(__file__).with_name('ros_peer.py'))


def mindgrasp(*args: str, timeout: float = 30) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=timeout, check=False)


def test_topic_and_node_commands(spawn_node):
    talker = spawn_node(PEER, 'talker', '--ros-args', '-r', '__ns:=/lab')
    assert talker.wait_for_output('ready')
    out = mindgrasp('topic', 'list', '-t').stdout
    assert '/lab/chatter [std_msgs/msg/String]' in out
    assert '/lab/peer_talker' in mindgrasp('node', 'list').stdout
    echo = mindgrasp('topic', 'echo', '/lab/chatter', '--once')
    assert echo.returncode == 0 and echo.stdout.startswith('data: hello ')
    field = mindgrasp('topic', 'echo', '/lab/chatter', '--once', '--field', 'data').stdout
    assert field.startswith('hello ')
    hz = mindgrasp('topic', 'hz', '/lab/chatter', '--duration', '2.5').stdout
    rate = float(hz.strip().splitlines()[-2].split(':')[1])
    assert 30 < rate < 70  # the talker publishes at 50 Hz
    info = mindgrasp('topic', 'info', '-v', '/lab/chatter').stdout
    assert 'Publisher count: 1' in info and 'Node name: peer_talker' in info
    assert 'Reliability: RELIABLE' in info
    node_info = mindgrasp('node', 'info', '/lab/peer_talker').stdout
    assert '/lab/chatter: std_msgs/msg/String' in node_info
    missing = mindgrasp('topic', 'echo', '/nope', '--once')
    assert missing.returncode == 1 and "Topic '/nope' was not found" in missing.stderr


def test_topic_pub_reaches_a_subscriber(spawn_node):
    echo = spawn_node(PEER, 'echo')
    assert echo.wait_for_output('ready')
    pub = mindgrasp('topic', 'pub', '/chatter', 'std_msgs/msg/String', '{data: from cli}',
                    '--times', '3', '--rate', '5')
    assert pub.returncode == 0, pub.stderr
    bad = mindgrasp('topic', 'pub', '/chatter', 'std_msgs/msg/String', '{text: x}', '--once')
    assert bad.returncode == 2 and "has no field 'text'" in bad.stderr   # usage error


def test_param_commands(spawn_node):
    spawn_node(PEER, 'params', '--ros-args', '-p', 'gain:=2.0')
    listing = mindgrasp('param', 'list', '/peer_params')
    assert listing.returncode == 0, listing.stderr
    assert '  gain\n' in listing.stdout and '  nested.level\n' in listing.stdout
    assert mindgrasp('param', 'get', '/peer_params', 'gain').stdout.strip() == \
        'Double value is: 2.0'
    assert mindgrasp('param', 'set', '/peer_params', 'gain', '5').returncode == 0
    assert mindgrasp('param', 'get', '/peer_params', 'gain', '--hide-type').stdout.strip() == '5.0'
    wrong = mindgrasp('param', 'set', '/peer_params', 'gain', 'abc')
    assert wrong.returncode == 1 and 'expected DOUBLE, got STRING' in wrong.stderr
