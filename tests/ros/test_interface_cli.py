"""`mindgrasp interface list|show|proto` and `mindgrasp --version`, run as a user runs them,
with ros2 interface's output format."""

import subprocess
import sys

import pytest
import yaml

from mindgrasp_common.resources import resource_path


def mindgrasp(*args: str, stdin: str | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args], input=stdin,
                          capture_output=True, text=True, timeout=60, check=False)


def test_list_has_headings_and_our_types():
    out = mindgrasp('interface', 'list').stdout.splitlines()
    assert [line for line in out if not line.startswith('    ')] == \
        ['Messages:', 'Services:', 'Actions:']
    assert '    mindgrasp_msgs/msg/MIPrediction' in out and '    std_msgs/msg/String' in out
    assert '    mindgrasp_msgs/srv/ResetSim' in out
    only = mindgrasp('interface', 'list', '-s').stdout.splitlines()
    assert only[0] == 'Services:' and '    std_srvs/srv/SetBool' in only
    assert not any('/msg/' in line or line == 'Messages:' for line in only)


def test_show_prints_the_file_and_expands_nested_types():
    srv = resource_path('mindgrasp_ros', 'interface_data', 'mindgrasp_msgs', 'srv',
                        'ResetSim.srv').read_text()
    assert mindgrasp('interface', 'show', 'mindgrasp_msgs/srv/ResetSim').stdout == srv
    bare = mindgrasp('interface', 'show', 'mindgrasp_msgs/srv/ResetSim', '--no-comments')
    assert bare.stdout == 'bool new_random_draw\nint64 seed\n---\nbool success\nstring message\n'
    nested = mindgrasp('interface', 'show', '-', stdin='mindgrasp_msgs/msg/MIPrediction\n')
    lines = nested.stdout.splitlines()
    at = lines.index('std_msgs/Header header')
    assert lines[at + 1:at + 5] == ['\tbuiltin_interfaces/Time stamp', '\t\tint32 sec',
                                    '\t\tuint32 nanosec', '\tstring frame_id']
    common = mindgrasp('interface', 'show', 'sensor_msgs/msg/CameraInfo').stdout.splitlines()
    assert 'float64[9] k' in common and 'float64[] d' in common


def test_proto_is_quoted_yaml_of_the_defaults():
    assert mindgrasp('interface', 'proto', 'geometry_msgs/msg/Quaternion').stdout == \
        '"x: 0.0\ny: 0.0\nz: 0.0\nw: 1.0\n"\n'
    assert mindgrasp('interface', 'proto', 'std_msgs/msg/Empty').stdout == '"{}\n"\n'
    req = mindgrasp('interface', 'proto', 'mindgrasp_msgs/srv/ResetSim', '--no-quotes').stdout
    assert yaml.safe_load(req) == {'new_random_draw': False, 'seed': 0}


@pytest.mark.parametrize('args', [('show', 'std_msgs/msg/Strin'), ('proto', 'nope/msg/X'),
                                  ('show', 'std_msgs/String')])
def test_unknown_interface_is_one_line_and_exit_2(args):
    run = mindgrasp('interface', *args)
    assert run.returncode == 2 and run.stdout == ''
    assert len(run.stderr.splitlines()) == 1 and args[1] in run.stderr


def test_version_is_the_installed_one():
    from importlib.metadata import version

    run = mindgrasp('--version')
    assert run.returncode == 0
    assert run.stdout.startswith(f'mindgrasp {version("mindgrasp-ros")}')
