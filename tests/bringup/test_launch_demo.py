"""The headless main demo, end to end: ``mindgrasp launch demo duration:=S`` starts every node,
ends cleanly and leaves a run directory whose bag holds the session."""

from __future__ import annotations

import uuid
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import run_launch

from mindgrasp_launch import LaunchService

pytestmark = pytest.mark.slow


def _missing_modules(profile: str) -> list[str]:
    plan = LaunchService(profile).plan(strict=False)
    return [str(spec.module) for spec in plan.processes if spec.problem]


@pytest.mark.timeout(1200)   # start-up waits for EEG, classifier and vision on a loaded machine
def test_demo_runs_headless_ends_cleanly_and_records_the_session(tmp_path: Path) -> None:
    assert not _missing_modules('demo'), 'every node of the demo is part of the project'
    run_dir = tmp_path / 'run'
    stream = f'mg-demo-test-{uuid.uuid4().hex[:8]}'  # LSL names are host-wide
    # generous stop timeout: this machine may be loaded by other test runs
    # one trial: the virtual subject (pursue) drives the arm to grasp the red cube; the trial
    # manager then ends the launch (duration is only a safety net)
    # the live view on a free port: several test runs share this host. The trial manager waits
    # until EEG, classifier and vision publish (a minute on a loaded machine) before the trial.
    # The trial itself takes ~30 s idle; on a host loaded by other suites the live loop (nine
    # processes in wall-clock time) can need several times that, so the test gives the trial
    # 300 s instead of the demo's 120 s: a deadline for the condition, not a measure of speed
    params = tmp_path / 'test_params.yaml'
    params.write_text(yaml.safe_dump({'trial_manager': {'ros__parameters': {
        'trial_timeout': 300.0}}}), encoding='utf-8')
    result = run_launch('demo', 'duration:=500', f'eeg_stream:={stream}', 'trials:=1',
                        'live_view_port:=0',
                        "targets:=red cube", '--sigint-timeout', '20', '--run-dir', str(run_dir),
                        timeout=900, MINDGRASP_PARAMS_FILES=str(params))
    assert result.returncode == 0, result.stderr[-4000:]
    summary = yaml.safe_load((run_dir / 'summary.yaml').read_text())
    assert {p['label'] for p in summary['processes']} == {
        'recorder', 'trial_manager', 'sim', 'virtual_amp', 'eeg_acquisition', 'classifier',
        'vision', 'fsm', 'foxglove_bridge'}
    log = (run_dir / 'logs' / 'trial_manager.log').read_text()
    # the live trial manager writes the same records as the lock-step experiments
    from mindgrasp_experiments.records import TrialRecord, read_records

    (record,) = read_records(run_dir / 'trials')
    assert isinstance(record, TrialRecord) and record.desired == 'red cube', record
    assert (run_dir / 'trials' / 'records.csv').read_text().splitlines()[0].split(',') == \
        TrialRecord.columns()
    # the live BCI loop chose an object and the controller went for it (state 5, grasp). Which
    # object, and whether the lift holds, depend on the subject (accuracy 0.9), the live decoder
    # and the wall-clock timing of nine processes on a possibly loaded host, so they are not this
    # test's condition: the record must say what happened, as the log does. The desired object
    # grasped through the same nodes is asserted where time is deterministic, in lock-step
    # (tests/experiments/test_experiment_cli.py: the virtual subject at accuracy 1 through the
    # decoder, and the oracle subject).
    assert '5' in record.states.split('-') and record.chosen, (record, log[-2000:])
    verdict = ('correct object grasped' if record.correct_and_successful else
               f'grasped the {record.grasped}' if record.success else f'failed ({record.failure}')
    assert f'Trial 1 (red cube): {verdict}' in log, (record, log[-2000:])
    for label in ('sim', 'eeg_acquisition', 'classifier', 'vision', 'fsm'):
        assert (run_dir / 'logs' / f'{label}.log').stat().st_size > 0, label
    from mindgrasp_bag.reader import BagReader

    with BagReader(run_dir / 'bag') as reader:
        reader.open()
        counts = {name: info.message_count for name, info in reader.topics.items()}
    for topic in ('/eeg/raw', '/joint_states', '/camera/color/image_raw', '/task/target',
                  '/bci/prediction', '/vision/detections', '/fsm/state'):
        assert counts.get(topic, 0) > 0, (topic, counts)
    # the simulator publishes a result when an object was lifted or dropped; a grasp that slips
    # before the lift (possible on a loaded host, 'no_grasp') publishes none
    if record.grasped:
        assert counts.get('/task/result', 0) > 0, (record, counts)
