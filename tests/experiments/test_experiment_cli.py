"""``mindgrasp experiment ...`` end to end: the experiment profile's real nodes (simulator, virtual
amplifier, classifier, vision, controller, trial manager) composed in lock-step on simulated
time, in subprocesses as a user runs them."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mindgrasp_experiments.records import read_records

HERE = Path(__file__).resolve().parent
FILES = ('records.csv', 'records.parquet', 'summary.json', 'report.md', 'time_to_grasp.png',
         'time_to_grasp.svg')


def mindgrasp(*args: str, timeout: float = 1200.0) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    # the user's own nodes (tests/experiments/user_nodes) for --launch
    env['PYTHONPATH'] = f"{HERE}{os.pathsep}{env.get('PYTHONPATH', '')}"
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=timeout, env=env, check=False)


def last_json(result: subprocess.CompletedProcess) -> dict:
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize(('args', 'message'), [
    (['set-locations', '--trials', '0'], 'argument --trials: must be >= 1, got 0'),
    (['set-locations', '--accuracy', '1.5'], 'argument --accuracy: must be between 0 and 1'),
    (['set-locations', '--seed', '-3'], 'argument --seed: must be >= 0, got -3'),
    (['random-locations', '--workers', '0'], 'argument --workers: must be >= 1, got 0'),
    (['random-locations', '--stall-timeout', 'nan'], "argument --stall-timeout: 'nan' is not"),
    (['random-locations', '--launch', 'nowhere.launch.py'], 'no such launch file'),
    (['random-locations', '--realism', 'foggy'], "--realism: Unknown realism profile 'foggy'"),
    (['set-locations', '--realism', 'foggy'], "--realism: Unknown realism profile 'foggy'"),
    (['report', 'no/such/run'], 'is not a directory'),
    (['set-locations', '--param', 'fsm.command_interface=joint_jog'],
     "--param fsm.command_interface: The parameter 'command_interface' is 'joint_jog'; use one "
     'of velocity, trajectory, servo_twist.'),
    (['random-locations', '--robot', 'ur5'], "--robot: No robot is named 'ur5'; use one of"),
])
def test_bad_input_is_one_clear_line_and_exit_2(args: list[str], message: str) -> None:
    result = mindgrasp('experiment', *args, timeout=120)
    assert result.returncode == 2, result.stderr
    lines = [ln for ln in result.stderr.splitlines() if ln.startswith('mindgrasp experiment')]
    assert len(lines) == 1 and message in lines[0], result.stderr
    assert 'Traceback' not in result.stderr


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_a_subject_that_decides_right_picks_the_desired_object_and_every_file_is_written(
        tmp_path: Path) -> None:
    """The oracle subject: the pursuing virtual subject at accuracy 1 with a perfect decoder
    (its intent is the prediction). It aims before it selects, so every trial goes for the
    desired object; the grasps mostly succeed."""
    out = tmp_path / 'run'
    s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '3', '--subject',
                            'oracle', '--seed', '2', '--out', str(out), '--json',
                            '--no-progress'))
    for name in (*FILES, 'set_location_map.png', 'set_location_map.svg'):
        assert (out / name).stat().st_size > 0, name
    records = read_records(out)
    assert [r.trial for r in records] == [1, 2, 3]
    assert all(r.correct_choice for r in records), [(r.desired, r.chosen, r.grasped, r.states)
                                                    for r in records]
    assert s['correct_and_successful_count'] >= 2, s
    assert s['trials'] == 3 and s['real_time_factor'] > 0 and s['cpu_s_per_sim_s'] > 0
    report = (out / 'report.md').read_text()
    assert '35.6 %' in report and 'Wilson 95 % CI' in report and 'real-time factor' in report
    # the report is rebuilt from the records alone
    (out / 'report.md').unlink()
    assert mindgrasp('experiment', 'report', str(out), timeout=300).returncode == 0
    assert (out / 'report.md').read_text() == report


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
@pytest.mark.parametrize('interface', ['trajectory', 'servo_twist'])
def test_the_oracle_grasps_through_a_trajectory_controller_and_moveit_servo(
        tmp_path: Path, interface: str) -> None:
    """Issue 28: the controller's commands as JointTrajectory or MoveIt Servo twists, which the
    simulator takes like a JointTrajectoryController or MoveIt Servo: the grasp succeeds."""
    out = tmp_path / 'run'
    s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '1', '--subject',
                            'oracle', '--out', str(out), '--json', '--no-progress', '--param',
                            f'fsm.command_interface={interface}'))
    assert s['correct_and_successful_count'] == 1, s
    assert f'command_interface: {interface}' in (out / 'params' / 'fsm.yaml').read_text()


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_the_virtual_subject_at_accuracy_1_picks_the_desired_object_through_the_decoder(
        tmp_path: Path) -> None:
    """EEG synthesis and the default decoder in the loop: a subject that always imagines the
    right class gets the desired object, although 11-14 % of its turning windows are decoded
    as both hands (benchmarks/selection.py; the controller's bci_select_dwell)."""
    out = tmp_path / 'run'
    s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '3', '--subject',
                            'virtual', '--accuracy', '1.0', '--seed', '1', '--workers', '2',
                            '--out', str(out), '--json', '--no-progress'))
    records = read_records(out)
    assert all(r.correct_and_successful for r in records), [
        (r.desired, r.chosen, r.grasped, r.states, r.online_accuracy) for r in records]
    assert s['online_accuracy'] < 0.98, s      # the decoder errs; the controller copes


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_same_seed_same_csv_with_1_and_2_workers(tmp_path: Path) -> None:
    """EEG synthesis, decoding, vision and physics in the loop: the records depend on the seed
    only. Trials are cut at 12 simulated s to keep the test short."""
    csv = []
    for workers in ('1', '2'):
        out = tmp_path / f'w{workers}'
        s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '2', '--subject',
                                'virtual', '--accuracy', '0.8', '--seed', '7', '--workers',
                                workers, '--trial-timeout', '12', '--out', str(out), '--json',
                                '--no-progress'))
        assert s['trials'] == 2
        csv.append((out / 'records.csv').read_text())
    assert csv[0] == csv[1]
    records = read_records(tmp_path / 'w1')
    assert all(r.subject == 'virtual' and r.n_predictions > 0 for r in records)
    assert all(math.isfinite(r.online_accuracy) for r in records)


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_noise_subject_runs(tmp_path: Path) -> None:
    s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '1', '--subject',
                            'noise', '--trial-timeout', '8', '--out', str(tmp_path / 'noise'),
                            '--json', '--no-progress'))
    (rec,) = read_records(tmp_path / 'noise')
    assert s['trials'] == 1 and rec.subject == 'noise' and rec.n_predictions > 0


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_random_locations_and_a_users_own_controller(tmp_path: Path) -> None:
    s = last_json(mindgrasp('experiment', 'random-locations', '--trials', '1', '--seed', '1',
                            '--out', str(tmp_path / 'auto'), '--json', '--no-progress'))
    assert s['trials'] == 1
    assert (tmp_path / 'auto' / 'random_location_scatter.svg').exists()
    # the user's controller replaces the node named fsm; it never grasps, so the trial is
    # aborted when its state stops changing
    out = tmp_path / 'own'
    s = last_json(mindgrasp('experiment', 'random-locations', '--trials', '1', '--seed', '1',
                            '--launch', str(HERE / 'user_nodes' / 'simple_controller.launch.py'),
                            '--stall-timeout', '4', '--out', str(out), '--json',
                            '--no-progress'))
    (rec,) = read_records(out)
    assert rec.failure == 'stalled' and 'no controller state change for 4 s' in rec.reason
    assert rec.states.startswith('1') and rec.path_length_m > 0.01


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
@pytest.mark.parametrize('robot', ['xarm6', 'panda'])
def test_random_locations_on_another_arm(robot: str, tmp_path: Path) -> None:
    """--robot xarm6: the same experiment runs the simulator, vision and the controller on the
    xArm6: its wrist camera finds the object, the controller centres it, approaches, closes the
    parallel jaws (grasp check by width) and lifts it above 0.22 m (about 14 simulated s).
    --robot panda: the same on the seven-joint Panda with its two-finger hand (centring with
    joint 6, turned the other way round; approach through the redundant grasp IK)."""
    s = last_json(mindgrasp('experiment', 'random-locations', '--robot', robot, '--trials', '1',
                            '--seed', '1', '--trial-timeout', '40', '--out', str(tmp_path),
                            '--json', '--no-progress'))
    assert s['trials'] == 1 and s['node_errors'] == 0
    (rec,) = read_records(tmp_path)
    assert rec.states == '1-2-3-4-5-6', (rec.states, rec.reason)
    assert rec.success and rec.correct_choice, rec.reason


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_a_node_raising_fails_its_trial_and_the_experiment_goes_on(tmp_path: Path) -> None:
    out = tmp_path / 'faulty'
    s = last_json(mindgrasp('experiment', 'random-locations', '--trials', '2', '--seed', '1',
                            '--launch', str(HERE / 'user_nodes' / 'faulty_controller.launch.py'),
                            '--out', str(out), '--json', '--no-progress'))
    assert s['trials'] == 2 and s['node_errors'] == 2
    for rec in read_records(out):
        assert rec.failure == 'node_error'
        assert "fsm" in rec.reason and 'simulated controller fault' in rec.reason



@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_ctrl_c_writes_the_finished_trials(tmp_path: Path) -> None:
    import signal
    import time

    out = tmp_path / 'stopped'
    env = dict(os.environ)
    # started as a script's background job is: with SIGINT ignored (inherited), which the
    # command must not keep (it ran all 50 trials through the Ctrl-C)
    proc = subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'experiment',
                             'random-locations', '--trials', '50', '--trial-timeout', '3',
                             '--out', str(out), '--no-progress'],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    # records.csv is rewritten after every finished trial: stop once it holds one
    deadline = time.monotonic() + 900
    csv = out / 'records.csv'
    while time.monotonic() < deadline and proc.poll() is None and (
            not csv.exists() or len(csv.read_text().splitlines()) < 2):
        time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    _stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr[-2000:]
    assert 'Interrupted: writing the' in stderr
    records = read_records(out)
    assert 0 < len(records) < 50
    assert [r.trial for r in records] == list(range(1, len(records) + 1))
    assert (out / 'report.md').exists() and 'Interrupted' in (out / 'report.md').read_text()


@pytest.mark.slow
@pytest.mark.timeout(1800)   # whole experiments in subprocesses, on a loaded machine
def test_launch_a_profile_in_lockstep(tmp_path: Path) -> None:
    """``mindgrasp launch <profile> --lockstep``: the profile's nodes on simulated time; the
    trial manager ends the launch and writes its record into the run directory."""
    run_dir = tmp_path / 'run'
    result = mindgrasp('launch', 'experiment', 'protocol:=random_locations',
                       'subject:=autonomous', 'trials:=1', 'seed:=3', '--lockstep',
                       '--run-dir', str(run_dir))
    assert result.returncode == 0, result.stderr[-3000:]
    assert "'eeg_acquisition'" not in result.stdout     # autonomous: no EEG nodes at all
    assert 'real-time factor' in result.stdout + result.stderr
    (rec,) = read_records(run_dir / 'trials')
    assert rec.trial == 1 and rec.protocol == 'random_locations' and rec.states.startswith('1')
