"""The headless main demo, end to end: ``mindgrasp launch demo duration:=S`` starts every node,
ends cleanly and leaves a run directory whose bag holds the session."""

from __future__ import annotations

import uuid
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import run_launch

from mindgrasp_bringup.launch_system import LaunchService

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
    # one trial: the virtual subject (pursue) must drive the arm to grasp the red cube; the
    # trial manager then ends the launch (duration is only a safety net)
    # the live view on a free port: several test runs share this host. The trial manager waits
    # until EEG, classifier and vision publish (a minute on a loaded machine) before the trial
    result = run_launch('demo', 'duration:=400', f'eeg_stream:={stream}', 'trials:=1',
                        'live_view_port:=0',
                        "targets:=red cube", '--sigint-timeout', '20', '--run-dir', str(run_dir),
                        timeout=900)
    assert result.returncode == 0, result.stderr[-4000:]
    summary = yaml.safe_load((run_dir / 'summary.yaml').read_text())
    assert {p['label'] for p in summary['processes']} == {
        'recorder', 'trial_manager', 'sim', 'virtual_amp', 'eeg_acquisition', 'classifier',
        'vision', 'fsm', 'foxglove_bridge'}
    log = (run_dir / 'logs' / 'trial_manager.log').read_text()
    assert 'Trial 1 (red cube): correct object grasped' in log, log[-2000:]
    # the live trial manager writes the same records as the lock-step experiments
    from mindgrasp_experiments.records import TrialRecord, read_records

    (record,) = read_records(run_dir / 'trials')
    assert isinstance(record, TrialRecord) and record.correct_and_successful
    assert (run_dir / 'trials' / 'records.csv').read_text().splitlines()[0].split(',') == \
        TrialRecord.columns()
    for label in ('sim', 'eeg_acquisition', 'classifier', 'vision', 'fsm'):
        assert (run_dir / 'logs' / f'{label}.log').stat().st_size > 0, label
    from mindgrasp_bringup.bag.reader import BagReader

    with BagReader(run_dir / 'bag') as reader:
        reader.open()
        counts = {name: info.message_count for name, info in reader.topics.items()}
    for topic in ('/eeg/raw', '/joint_states', '/camera/color/image_raw', '/task/target',
                  '/bci/prediction', '/vision/detections', '/fsm/state', '/task/result'):
        assert counts.get(topic, 0) > 0, (topic, counts)
