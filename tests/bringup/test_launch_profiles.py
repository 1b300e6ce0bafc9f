"""What each launch profile starts, resolved without starting anything."""

from __future__ import annotations

import pytest

from mindgrasp_launch import LaunchError, LaunchService, profiles


def processes(profile: str, *args: str) -> dict[str, object]:
    plan = LaunchService(profile, list(args)).plan(strict=False)
    for spec in plan.processes:  # a missing node module is the only acceptable problem
        assert spec.problem is None or 'does not exist (yet)' in spec.problem, spec.problem
    return {spec.label: spec for spec in plan.processes}


def test_mine_and_the_helpers_profiles_exist() -> None:
    assert {'demo', 'trainer', 'graz', 'hardware', 'replay'} <= set(profiles())


def test_demo_starts_every_node_after_the_recorder() -> None:
    procs = processes('demo', 'seed:=4', 'eeg_stream:=amp-x')
    assert list(procs) == ['recorder', 'trial_manager', 'sim', 'virtual_amp', 'eeg_acquisition',
                           'classifier', 'vision', 'fsm', 'foxglove_bridge']
    assert procs['foxglove_bridge'].parameters['port'] == 8765
    assert 'foxglove_bridge' not in processes('demo', 'live_view:=false')
    assert procs['trial_manager'].parameters['targets'] == 'red cube, blue cylinder, yellow sphere'
    assert procs['trial_manager'].parameters['n_trials'] == 3
    assert procs['trial_manager'].parameters['seed'] == 4
    assert processes('demo', 'trials:=3')['trial_manager'].parameters['n_trials'] == 3
    assert procs['recorder'].daemon
    assert procs['sim'].module == 'mindgrasp_sim.sim_node'
    assert procs['sim'].parameters['seed'] == 4 and procs['sim'].parameters['gui'] is False
    assert procs['virtual_amp'].parameters['stream_name'] == 'amp-x'
    assert procs['eeg_acquisition'].parameters['stream_name'] == 'amp-x'
    assert procs['virtual_amp'].parameters['subject_mode'] == 'pursue'
    procs = processes('demo', 'record:=false', 'gui:=true')
    assert 'recorder' not in procs and procs['sim'].parameters['gui'] is True


#: the amplifier's stream pinned (source id and host), as the hardware profile requires
PIN = ('eeg_source_id:=amp-1', 'eeg_host:=local')

#: every node that reads the robot description, per profile (plus what each profile needs)
ROBOT_READERS = {
    'sim': ((), ('sim',)),
    'demo': ((), ('sim', 'fsm', 'foxglove_bridge', 'virtual_amp')),
    'experiment': ((), ('sim', 'fsm', 'virtual_amp')),   # the oracle subject too (subject:=oracle)
    'trainer': ((), ('sim', 'fsm', 'trainer')),
    'hardware': (('eeg_stream:=amp', 'eeg_source_id:=amp-1', 'eeg_host:=local', 'arm_driver:=true',
                  'model:=package://mindgrasp_classifier/models/default_classifier.json'),
                 ('fsm',)),
    'replay': (('bag:=runs/x',), ('replay',)),
    'graz': ((), ()),
}


def test_the_robot_reaches_the_simulator_and_the_controller() -> None:
    assert processes('sim')['sim'].parameters['robot'] == 'mindgrasp_arm'
    assert processes('sim', 'robot:=xarm6')['sim'].parameters['robot'] == 'xarm6'
    for profile in ('demo', 'experiment'):
        procs = processes(profile, 'robot:=xarm6')
        assert procs['sim'].parameters['robot'] == procs['fsm'].parameters['robot'] == 'xarm6'


@pytest.mark.parametrize('profile', sorted(ROBOT_READERS))
def test_every_profile_passes_robot_to_every_node_that_reads_it(profile) -> None:
    extra, readers = ROBOT_READERS[profile]
    procs = processes(profile, *extra, 'robot:=xarm6')
    given = {label for label, spec in procs.items() if spec.parameters.get('robot') == 'xarm6'}
    assert given == set(readers)
    # the default: the shipped arm, or (replay) the robot the recorded run used
    default = '' if profile == 'replay' else 'mindgrasp_arm'
    assert all(processes(profile, *extra)[r].parameters['robot'] == default for r in readers)
    # the bag's metadata.yaml names the robot (custom_data), the replay's the recorded run's
    custom = procs['recorder'].parameters.get('custom_data')
    assert custom == ['robot=xarm6']
    assert processes(profile, *extra)['recorder'].parameters.get('custom_data') == (
        None if profile == 'replay' else ['robot=mindgrasp_arm'])


def test_hardware_has_drivers_and_no_simulator(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)            # model:= must name an existing file
    (tmp_path / 'models').mkdir()
    (tmp_path / 'models' / 'alice.json').write_text('{}')
    procs = processes('hardware', 'eeg_stream:=gNautilus', *PIN, 'arm_driver:=true',
                      'arm_driver_args:=--ip "10.0.0.2" --rate 100', 'model:=models/alice.json')
    assert 'sim' not in procs and 'virtual_amp' not in procs and 'camera_driver' not in procs
    driver = procs['arm_driver']
    assert driver.program[0].endswith('/true') and driver.node_name == 'arm_driver'
    assert driver.arguments == ['--ip', '10.0.0.2', '--rate', '100']
    assert driver.required and driver.shutdown_on_exit     # its end stops the launch
    assert procs['eeg_acquisition'].parameters['stream_name'] == 'gNautilus'
    assert procs['classifier'].parameters['model'] == 'models/alice.json'
    procs = processes('hardware', 'eeg_stream:=a', *PIN, 'arm_driver:=true', 'camera_driver:=true',
                      'model:=models/alice.json')
    assert 'camera_driver' in procs and procs['camera_driver'].required
    # package/executable: our module, else `ros2 run package executable`
    procs = processes('hardware', 'eeg_stream:=a', *PIN, 'arm_driver:=mindgrasp_sim/sim_node',
                      'model:=models/alice.json')
    assert procs['arm_driver'].module == 'mindgrasp_sim.sim_node'
    with pytest.raises(LaunchError, match=r"needs these arguments, which were not given: "
                                          r"eeg_stream:=<value>.*; arm_driver:=<value>"):
        LaunchService('hardware').plan()
    with pytest.raises(LaunchError, match="'no-such-arm-driver' was found neither on PATH"):
        LaunchService('hardware', ['eeg_stream:=a', *PIN, 'arm_driver:=no-such-arm-driver',
                                   'model:=models/alice.json', 'record:=false']).plan()


def test_hardware_never_decodes_a_person_with_the_simulated_head_silently(tmp_path,
                                                                         monkeypatch) -> None:
    """Issue 31, item 9: without model:= the hardware profile used the classifier trained on
    the simulated head, without a word. Now it refuses in one line naming both fixes; a bench
    test names that model on purpose."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(LaunchError, match=r"launch argument 'model' is required and was not "
                                          r"given: add model:=<value> \(the person's classifier "
                                          r'.*model:=package://mindgrasp_classifier/models/'
                                          r'default_classifier\.json\)'):
        LaunchService('hardware', ['eeg_stream:=a', 'arm_driver:=true']).plan()
    bench = 'package://mindgrasp_classifier/models/default_classifier.json'
    procs = processes('hardware', 'eeg_stream:=a', *PIN, 'arm_driver:=true', f'model:={bench}')
    assert procs['classifier'].parameters['model'] == bench


def test_replay_runs_the_lockstep_replay_process_with_its_arguments(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'x.json').write_text('{}')
    procs = processes('replay', 'bag:=/data/run')
    assert list(procs) == ['recorder', 'replay']
    node = procs['replay']
    assert node.module == 'mindgrasp_bringup.replay.replay_node' and node.shutdown_on_exit
    assert node.parameters['bag'] == '/data/run' and node.parameters['controller'] is False
    procs = processes('replay', 'bag:=b', 'controller:=true', 'model:=x.json')
    assert procs['replay'].parameters['controller'] is True
    assert procs['replay'].parameters['model'] == 'x.json'


def test_trainer_and_graz_end_with_their_prompter(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'm.json').write_text('{}')
    procs = processes('trainer', 'trials:=8', 'amp:=lsl', 'eeg_stream:=amp')
    assert 'virtual_amp' not in procs and list(procs)[-1] == 'trainer'
    assert procs['trainer'].shutdown_on_exit and procs['trainer'].parameters['n_trials'] == 8
    assert procs['sim'].parameters['trainer_robot'] is True
    procs = processes('trainer')
    assert procs['virtual_amp'].parameters['subject_mode'] == 'follow'
    procs = processes('graz')
    assert list(procs) == ['recorder', 'virtual_amp', 'eeg_acquisition', 'graz_prompter']
    assert procs['graz_prompter'].module == 'mindgrasp_trainer.graz_node'
    procs = processes('graz', 'feedback:=true', 'model:=m.json')
    assert procs['classifier'].parameters['model'] == 'm.json'


def test_a_profile_can_be_included_by_name() -> None:
    from mindgrasp_launch import (
        IncludeLaunchDescription,
        LaunchDescription,
        PythonLaunchDescriptionSource,
    )

    description = LaunchDescription([
        IncludeLaunchDescription(PythonLaunchDescriptionSource('eeg'),
                                 launch_arguments={'virtual_amp': 'true',
                                                   'eeg_stream': 'inner-amp'}),
    ])
    plan = LaunchService(description, ['record:=false', 'seed:=7']).plan(strict=False)
    procs = {p.label: p for p in plan.processes}
    assert list(procs) == ['virtual_amp', 'eeg_acquisition']
    assert procs['virtual_amp'].parameters['stream_name'] == 'inner-amp'
    assert procs['virtual_amp'].parameters['seed'] == 7  # the including launch's argument


@pytest.mark.parametrize('profile', ['demo', 'experiment', 'hardware'])
def test_command_interface_reaches_the_controller(profile: str, tmp_path, monkeypatch) -> None:
    """Issue 28: ``command_interface:=`` of the profiles sets the fsm node's parameter; a value
    that is not an interface is refused before anything starts, naming the choices."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'alice.json').write_text('{}')
    extra = {'hardware': ['eeg_stream:=a', *PIN, 'arm_driver:=true',
                          'model:=alice.json']}.get(profile, [])
    assert processes(profile, *extra)['fsm'].parameters['command_interface'] == 'velocity'
    for interface in ('trajectory', 'servo_twist'):
        fsm = processes(profile, *extra, f'command_interface:={interface}')['fsm']
        assert fsm.parameters['command_interface'] == interface
    with pytest.raises(LaunchError, match=r"'joint_jog'.*velocity, trajectory, servo_twist"):
        processes(profile, *extra, 'command_interface:=joint_jog')


def test_hardware_refuses_an_unpinned_stream_before_anything_starts(tmp_path, monkeypatch):
    """Issue 42: any LSL sender of the stream's name (another rig, a demo's virtual amplifier)
    could drive the arm. Without eeg_source_id and eeg_host the launch is refused in one line;
    eeg_unpinned:=true accepts any sender on purpose (a bench test)."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'alice.json').write_text('{}')
    args = ['eeg_stream:=gNautilus', 'arm_driver:=true', 'model:=alice.json']
    with pytest.raises(LaunchError, match=r"the EEG stream 'gNautilus' is not pinned "
                                          r"\(eeg_source_id and eeg_host not given\).*"
                                          r'eeg_unpinned:=true for a bench test'):
        LaunchService('hardware', args).plan()
    with pytest.raises(LaunchError, match=r'not pinned \(eeg_host not given\)'):
        LaunchService('hardware', [*args, 'eeg_source_id:=GN-1']).plan()
    acquisition = processes('hardware', *args, *PIN)['eeg_acquisition'].parameters
    assert (acquisition['source_id'], acquisition['hostname'], acquisition['allow_unpinned']) == \
        ('amp-1', 'local', False)
    acquisition = processes('hardware', *args, 'eeg_unpinned:=true')['eeg_acquisition'].parameters
    assert acquisition['allow_unpinned'] is True and acquisition['source_id'] == ''


def test_the_demo_pins_its_acquisition_to_its_own_amplifier() -> None:
    """Issue 42: a source id made per run, the same for the amplifier and the acquisition (on
    this host), another one for the next run."""
    first, second = processes('demo'), processes('demo')
    amp, acquisition = (first['virtual_amp'].parameters, first['eeg_acquisition'].parameters)
    assert amp['source_id'] == acquisition['source_id'] and acquisition['hostname'] == 'local'
    assert amp['source_id'].startswith('mindgrasp-')
    assert second['virtual_amp'].parameters['source_id'] != amp['source_id']
