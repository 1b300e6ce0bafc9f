"""`mindgrasp param dump|load` against the controller node in another process (real DDS): a
dump is a parameter file that `--params-file` and `param load` read back, as with ros2."""

import subprocess
import sys

import pytest
import yaml

pytestmark = pytest.mark.slow

READY = 'Grasp controller ready'


def mindgrasp(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=timeout, check=False)


def dump(node: str = '/fsm') -> dict:
    run = mindgrasp('param', 'dump', node)
    assert run.returncode == 0, run.stderr
    return yaml.safe_load(run.stdout)


def test_dump_round_trips_through_params_file_and_load(spawn_node, tmp_path):
    first = spawn_node('mindgrasp_fsm.fsm_node')
    assert first.wait_for_output(READY, 60), first.output()
    saved = mindgrasp('param', 'dump', '/fsm', '--output-dir', str(tmp_path))
    assert saved.returncode == 0, saved.stderr
    path = tmp_path / 'fsm.yaml'
    assert saved.stdout.strip() == f'Saving to:  {path}'
    data = yaml.safe_load(path.read_text())
    params = data['/fsm']['ros__parameters']
    assert params['lock_duration'] == 1.0 and params['approach_joint'] == 2
    assert data == dump()   # the file and the printed dump are the same
    first.stop()

    # a read-only and a live value changed in the file: a new node started with it has them
    params['approach_joint'], params['lock_duration'] = 3, 2.5
    path.write_text(yaml.safe_dump(data))
    second = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '--params-file', str(path))
    assert second.wait_for_output(READY, 60), second.output()
    assert dump() == data

    # param load: the live change is applied, the read-only one refused with the reason
    params['approach_joint'], params['lock_duration'] = 4, 0.75
    path.write_text(yaml.safe_dump(data))
    load = mindgrasp('param', 'load', '/fsm', str(path))
    assert load.returncode == 0, load.stderr
    assert 'Set parameter lock_duration successful' in load.stdout.splitlines()
    assert 'Set parameter approach_joint failed: ' in load.stderr and 'read-only' in load.stderr
    now = dump()['/fsm']['ros__parameters']
    assert (now['lock_duration'], now['approach_joint']) == (0.75, 3)


def test_dump_and_load_bad_input_is_one_line(tmp_path):
    other = tmp_path / 'other.yaml'
    other.write_text('/sim:\n  ros__parameters: {gui: false}\n')
    broken = tmp_path / 'broken.yaml'
    broken.write_text('/fsm: [\n')
    for args, expected in [
        (('load', '/fsm', str(tmp_path / 'missing.yaml')), 'does not exist'),
        (('load', '/fsm', str(other)), "has no '/fsm: ros__parameters:' section"),
        (('load', '/fsm', str(broken)), 'is not valid YAML'),
        (('dump', '/fsm', '--output-dir', str(tmp_path / 'nodir')), 'is not a directory'),
    ]:
        run = mindgrasp('param', *args)
        assert run.returncode == 2, (args, run.stderr)
        assert expected in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr


def test_load_takes_the_wildcard_section_only_when_asked(tmp_path):
    from mindgrasp_ros.runtime.arguments import load_params_file

    path = tmp_path / 'p.yaml'
    path.write_text("/**:\n  ros__parameters: {use_sim_time: true}\n"
                    "/fsm:\n  ros__parameters: {lock_duration: 2.0}\n")
    assert load_params_file(path, '/fsm') == {'use_sim_time': True, 'lock_duration': 2.0}
    assert load_params_file(path, '/fsm', use_wildcard=False) == {'lock_duration': 2.0}
