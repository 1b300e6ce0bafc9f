"""`mindgrasp service list|type|call` against the simulator node in another process (real DDS),
as `ros2 service` prints them."""

import subprocess
import sys

import pytest

pytestmark = pytest.mark.slow


def mindgrasp(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=timeout, check=False)


def test_service_verbs_against_the_sim_node(spawn_node):
    sim = spawn_node('mindgrasp_sim.sim_node', duration=300.0, camera_rate=1.0)
    assert sim.wait_for_output('Simulating scene', 120), sim.output()
    listing = mindgrasp('service', 'list', '-t')
    assert listing.returncode == 0, listing.stderr
    lines = listing.stdout.splitlines()
    assert '/sim/reset [mindgrasp_msgs/srv/ResetSim]' in lines
    assert '/sim/load_scene [mindgrasp_msgs/srv/LoadScene]' in lines
    assert '/sim/set_parameters [rcl_interfaces/srv/SetParameters]' in lines
    assert lines == sorted(lines)
    names = mindgrasp('service', 'list').stdout.splitlines()
    assert names == [line.split(' [')[0] for line in lines]
    assert int(mindgrasp('service', 'list', '-c').stdout) == len(lines)

    typed = mindgrasp('service', 'type', '/sim/reset')
    assert (typed.returncode, typed.stdout) == (0, 'mindgrasp_msgs/srv/ResetSim\n')
    missing = mindgrasp('service', 'type', '/sim/nope')
    assert missing.returncode == 1 and missing.stdout == ''
    assert len(missing.stderr.splitlines()) == 1 and "'/sim/nope' is not on" in missing.stderr

    call = mindgrasp('service', 'call', '/sim/reset', 'mindgrasp_msgs/srv/ResetSim',
                     '{seed: 7}')
    assert call.returncode == 0, call.stderr
    assert ('requester: making request: mindgrasp_msgs.srv.ResetSim_Request('
            'new_random_draw=False, seed=7)\n\nresponse:\n'
            'mindgrasp_msgs.srv.ResetSim_Response(success=True, ') in call.stdout
    assert 'Reset: robots home' in call.stdout
    # interface proto's quoted YAML is what a user pastes into service call
    proto = mindgrasp('interface', 'proto', 'mindgrasp_msgs/srv/ResetSim').stdout.strip()
    pasted = mindgrasp('service', 'call', '/sim/reset', 'mindgrasp_msgs/srv/ResetSim',
                       proto.strip('"'))
    assert pasted.returncode == 0 and 'ResetSim_Response(success=True' in pasted.stdout


@pytest.mark.parametrize(('args', 'expected'), [
    (('/sim/reset', 'mindgrasp_msgs/srv/Nope'), "Unknown srv type 'mindgrasp_msgs/srv/Nope'"),
    (('/sim/reset', 'ResetSim'), "'ResetSim' is not a service type"),
    (('/sim/reset', 'mindgrasp_msgs/ResetSim', '{sed: 1}'), "has no field 'sed'"),
    (('/sim/reset', 'mindgrasp_msgs/ResetSim', '{seed: [}'), 'not valid YAML'),
    (('/sim/reset', 'mindgrasp_msgs/ResetSim', '[1]'), 'must be a YAML mapping'),
])
def test_service_call_bad_input_is_one_line_and_exit_2(args, expected):
    """Refused before any DDS traffic: one line naming the problem, exit 2 (usage)."""
    run = mindgrasp('service', 'call', *args)
    assert run.returncode == 2 and run.stdout == ''
    assert len(run.stderr.splitlines()) == 1 and expected in run.stderr


def test_service_call_of_an_absent_service_ends_after_timeout():
    run = mindgrasp('service', 'call', '/absent', 'std_srvs/srv/Trigger', '--timeout', '1')
    assert run.returncode == 1
    assert run.stderr.strip().endswith('check the name with `mindgrasp service list` and the '
                                       'ROS_DOMAIN_ID.')
