"""Replay as an experiment on recorded data: a real demo run (processes, DDS, LSL, PyBullet, MCAP)
is replayed; the classifier's replayed predictions equal the recorded ones, the controller is
replayed open loop, and the report has every file."""

from __future__ import annotations

import itertools
import json
import shutil
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import launch_cmd, launch_env, run_launch

from conftest_bag import EEG, cut_in_half, damage_chunks, eeg_chunk
from mindgrasp_bag import BagWriter
from mindgrasp_bag.mcap_scan import read_mcap_contents
from mindgrasp_common.robot_description import load_robot

pytestmark = pytest.mark.slow

REPORT_FILES = ('report.md', 'comparison.json', 'predictions.csv', 'timeline.png',
                'replayed_bag/metadata.yaml', 'params/classifier.yaml')


@pytest.fixture(scope='module')
def demo_run(tmp_path_factory) -> Path:
    """A live demo (every node in its own process, recorded to run/bag), stopped with Ctrl-C once
    the bag holds a few seconds of predictions: start-up takes long on a loaded machine."""
    run_dir = tmp_path_factory.mktemp('replay') / 'run'
    stream = f'mg-replay-test-{uuid.uuid4().hex[:8]}'  # LSL names are host-wide
    # the live view on a free port: a demo in another suite or session may hold 8765
    proc = subprocess.Popen(launch_cmd('demo', 'duration:=400', 'trials:=0', 'live_view_port:=0',
                                       f'eeg_stream:={stream}', '--sigint-timeout', '20',
                                       '--run-dir', str(run_dir)),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            env=launch_env())
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True).start()
    try:
        deadline = time.monotonic() + 300
        predictions = 0
        while time.monotonic() < deadline and proc.poll() is None and predictions < 80:
            time.sleep(2.0)
            if any('Subscribed to /bci/prediction' in line for line in lines):
                contents = read_mcap_contents(run_dir / 'bag' / 'bag_0.mcap')
                predictions = sum(n for cid, n in contents.channel_counts.items()
                                  if contents.channels[cid].topic == '/bci/prediction')
        assert predictions >= 80, ''.join(lines[-50:])
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        proc.wait(180)
    assert (run_dir / 'summary.yaml').exists(), ''.join(lines[-50:])
    return run_dir


def _mindgrasp(*args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, env=launch_env(), timeout=timeout)


def test_replayed_predictions_equal_the_recorded_ones(demo_run, tmp_path):
    out = tmp_path / 'report'
    done = _mindgrasp('replay', str(demo_run), '--json', '-o', str(out), '--min-agreement', '1')
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    pred = summary['topics']['/bci/prediction']
    assert pred['comparable'] >= 60, pred          # several seconds of decoded EEG
    assert summary['prediction_agreement'] == 1.0, pred
    assert pred['agree'] == pred['comparable'] and pred['missing'] == 0
    assert pred['max_certainty_difference'] == 0.0   # the same windows, bit for bit
    assert summary['report_path'] == str(out / 'report.md')
    for name in REPORT_FILES:
        assert (out / name).exists(), name
    assert 'Replayed classifier: predictions' in done.stdout
    assert '100.0 %' in (out / 'report.md').read_text()


def _damaged_copy(demo_run: Path, tmp_path: Path, damage) -> Path:
    run = tmp_path / 'run'
    shutil.copytree(demo_run, run, ignore=shutil.ignore_patterns('replays'))
    damage(run / 'bag' / 'bag_0.mcap')
    return run


def test_replay_of_a_bag_cut_in_half_says_so_and_fails_its_check(demo_run, tmp_path):
    run = _damaged_copy(demo_run, tmp_path, cut_in_half)
    done = _mindgrasp('replay', str(run), '--json', '--no-progress', '-o', str(tmp_path / 'r'))
    assert done.returncode == 1, done.stdout[-3000:] + done.stderr[-3000:]
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    damage = summary['damage']
    assert damage['damaged'] and damage['cut_files'] == 1
    assert 0 < damage['readable_messages'] < damage['expected_messages']
    assert damage['lost_messages'] == damage['expected_messages'] - damage['readable_messages']
    assert damage['lost_span_s'] > 1.0
    assert any('Damaged bag' in n for n in summary['notes'])
    # the check fails even where the readable half agrees: its damage is not accepted
    assert 'pass --allow-damaged' in done.stderr and 'Traceback' not in done.stderr


def test_replay_of_a_bag_with_three_damaged_chunks_reads_the_rest(demo_run, tmp_path):
    run = _damaged_copy(demo_run, tmp_path, damage_chunks)
    done = _mindgrasp('replay', str(run), '--json', '--no-progress', '-o', str(tmp_path / 'r'),
                      '--allow-damaged')
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    assert summary['damage']['skipped_records'] == 3
    assert summary['damage']['lost_messages'] > 0
    assert summary['fed']['/eeg/raw'] > 0
    assert 'The agreement covers the readable part only.' in done.stderr


def test_launch_replay_with_the_controller_reports_it_open_loop(demo_run, tmp_path):
    out = tmp_path / 'report'
    # robot:= reaches the re-run controller (the run's own arm, named by its description file)
    robot = str(load_robot('mindgrasp_arm').path)
    result = run_launch('replay', f'bag:={demo_run / "bag"}', 'controller:=true',
                        f'output:={out}', 'record:=false', f'robot:={robot}', timeout=600)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    summary = json.loads((out / 'comparison.json').read_text())
    assert summary['open_loop'] is True and summary['nodes'] == ['classifier', 'controller']
    state = summary['topics']['/fsm/state']
    assert state['open_loop'] is True and state['replayed_messages'] > 0
    assert summary['prediction_agreement'] == 1.0
    report = (out / 'report.md').read_text()
    assert '## Controller replayed open loop' in report
    assert 'the joint states, camera images and detections it read are the recorded ones' \
        in report
    for name in (*REPORT_FILES, 'states.csv', 'params/fsm.yaml'):
        assert (out / name).exists(), name
    params = yaml.safe_load((out / 'params' / 'fsm.yaml').read_text())
    assert params['/fsm']['ros__parameters']['robot'] == robot


def test_replay_bad_input_is_one_clear_line(tmp_path):
    done = _mindgrasp('replay', str(tmp_path / 'nothing'))
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        f'mindgrasp replay: {tmp_path / "nothing"} does not exist; pass a run directory '
        '(runs/<run>) or its bag folder (runs/<run>/bag).']
    done = _mindgrasp('replay', str(tmp_path), '-p', 'vision.x:=1')
    assert done.returncode == 2 and 'is not NODE.NAME:=VALUE' in done.stderr
    with BagWriter(tmp_path / 'bag') as writer:   # a bag without EEG
        writer.add_topic('/chatter', 'std_msgs/msg/String')
        writer.write('/chatter', 1, bytes([0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]))
    done = _mindgrasp('replay', str(tmp_path / 'bag'), '--no-progress')
    assert done.returncode == 2 and 'has no /eeg/raw messages' in done.stderr
    assert 'Traceback' not in done.stderr
    run = tmp_path / 'old_run'                   # a run whose classifier model is gone
    with BagWriter(run / 'bag') as writer:
        writer.add_topic('/eeg/raw', EEG)
        writer.write('/eeg/raw', 1, eeg_chunk(0))
    (run / 'params.yaml').write_text('/classifier:\n  ros__parameters: {model: /no/model.json}\n')
    done = _mindgrasp('replay', str(run), '--no-progress')
    assert done.returncode == 2, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith('mindgrasp replay: The classifier node cannot start with the '
                           'parameters of the run (') and '-p classifier.NAME:=VALUE' in last
    assert 'Traceback' not in done.stderr


def test_export_of_the_demo_run_carries_targets_states_and_the_montage(demo_run, tmp_path):
    import mne

    out = tmp_path / 'demo_raw.fif'
    done = _mindgrasp('export', 'eeg', str(demo_run), '--format', 'fif', '-o', str(out))
    assert done.returncode == 0, done.stdout + done.stderr
    raw = mne.io.read_raw_fif(out, verbose='error')
    tags = {d.split('/')[0] for d in raw.annotations.description}
    assert {'target', 'state', 'intent'} <= tags, tags
    states = [d for d in raw.annotations.description if d.startswith('state/')]
    assert all(a != b for a, b in itertools.pairwise(states))   # changes only
    positions = raw.get_montage().get_positions()['ch_pos']
    assert 'C3' in positions and positions['C3'][0] < 0
