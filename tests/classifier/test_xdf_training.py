"""Training from a LabRecorder-style XDF: a live Graz run whose events the ``lsl_markers`` node
mirrors to LSL, recorded with the amplifier's EEG by an independent LSL inlet
(``lsl_recorder.py``, as LabRecorder records), trains a classifier that scores as the one trained
from the same run's bag.

Every part is real: the virtual amplifier's LSL stream, the marker node, the launch (acquisition,
Graz prompter, recorder) over DDS, the XDF read with pyxdf, the bag with rosbags.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import uuid
from pathlib import Path

import numpy as np
import pytest
import yaml

from mindgrasp_classifier.data import load_bag, load_xdf
from mindgrasp_ros.node_process import NodeProcess

pytestmark = pytest.mark.slow
HERE = Path(__file__).resolve().parent
MG = [sys.executable, '-m', 'mindgrasp_cli']
TRIALS = 8


@pytest.fixture(scope='module')
def graz_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """(run directory, XDF file) of one live Graz run of 8 trials recorded both ways."""
    tmp = tmp_path_factory.mktemp('xdf')
    eeg, markers = (f'mg-xdf-{kind}-{uuid.uuid4().hex[:8]}' for kind in ('eeg', 'markers'))
    env = {**os.environ, 'PYTHONUNBUFFERED': '1', 'NO_COLOR': '1'}
    amp = NodeProcess('mindgrasp_eeg.virtual_amp_node', [
        '--ros-args', '-p', f'stream_name:={eeg}', '-p', 'subject_mode:=follow', '-p',
        'seed:=0'], env, tmp / 'amp.log')
    mirror = NodeProcess('mindgrasp_eeg.marker_node', [
        '--ros-args', '-p', f'stream_name:={markers}', '-p', f'source_id:={markers}'], env,
        tmp / 'markers.log')
    xdf = tmp / 'session.xdf'
    log = (tmp / 'recorder.log').open('w')     # liblsl's own log lines go to stderr
    recorder = subprocess.Popen([sys.executable, str(HERE / 'lsl_recorder.py'), '--eeg', eeg,
                                 '--markers', markers, '--out', str(xdf)],
                                stdout=subprocess.PIPE, stderr=log, text=True)
    try:
        # the recorder waits (120 s at most) for both streams and says READY with its inlets open,
        # so it hears every prompt: the run starts after it (or it ends, and the loop with it)
        lines = iter(recorder.stdout.readline, '')
        assert any(line.strip() == 'READY' for line in lines), (tmp / 'recorder.log').read_text()
        params = tmp / 'graz.yaml'
        params.write_text(yaml.safe_dump({'graz_prompter': {'ros__parameters': {
            'fixation': 0.5, 'cue': 1.0, 'imagery': 1.6, 'rest_min': 0.3, 'rest_max': 0.5,
            'wait_for_eeg': True}}}), encoding='utf-8')
        run_dir = tmp / 'run'
        launch = subprocess.run(
            [*MG, 'launch', 'graz', 'amp:=lsl', f'eeg_stream:={eeg}', 'markers:=false',
             f'trials:={TRIALS}', '--run-dir', str(run_dir)],
            env={**env, 'MINDGRASP_PARAMS_FILES': str(params)}, capture_output=True, text=True,
            timeout=600)
        assert launch.returncode == 0, launch.stderr[-3000:]
        recorder.send_signal(signal.SIGINT)
        out, _ = recorder.communicate(timeout=120)
        assert recorder.returncode == 0 and xdf.is_file(), out + (tmp / 'recorder.log').read_text()
    finally:
        if recorder.poll() is None:
            recorder.kill()
        log.close()
        mirror.stop()
        amp.stop()
    return run_dir, xdf


def _train(tmp: Path, *data: str) -> dict:
    res = subprocess.run([*MG, 'train', 'classifier', *data, '--min-trials', '2', '--cv', '2',
                          '-o', str(tmp / 'model'), '--json'], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1])


@pytest.mark.timeout(900)
def test_the_xdf_holds_the_runs_cues_at_the_bags_times(graz_run: tuple[Path, Path]) -> None:
    run_dir, xdf = graz_run
    from_xdf, from_bag = load_xdf(xdf), load_bag(run_dir)
    assert from_xdf.rate == from_bag.rate == 250.0
    assert from_xdf.channels == from_bag.channels
    # the same trials, in the same order, the same time apart (within 2 samples = 8 ms)
    assert from_xdf.events[:, 1].tolist() == from_bag.events[:, 1].tolist()
    assert len(from_bag.events) == TRIALS
    np.testing.assert_allclose(np.diff(from_xdf.events[:, 0]), np.diff(from_bag.events[:, 0]),
                               atol=2)
    # and the same EEG: the amplifier's samples one second after the first cue are in both, at
    # most 5 samples (20 ms) apart. The two place a cue by different clocks (the marker's LSL
    # time, the prompt's ROS stamp through the EEG's stamps), and a loaded machine put them a
    # sample or more apart: the samples are looked for, not assumed at the same index
    start_x, start_b = from_xdf.events[0, 0], from_bag.events[0, 0]
    segment = from_bag.data[start_b + 250: start_b + 260]
    offsets = [k for k in range(-25, 26) if np.allclose(
        from_xdf.data[start_x + 250 + k: start_x + 260 + k], segment, rtol=0, atol=1e-9)]
    assert len(offsets) == 1 and abs(offsets[0]) <= 5, offsets


@pytest.mark.timeout(900)
def test_a_classifier_trained_from_the_xdf_scores_as_one_from_the_bag(
        graz_run: tuple[Path, Path], tmp_path: Path) -> None:
    run_dir, xdf = graz_run
    from_xdf = _train(tmp_path / 'x', '--xdf', str(xdf))
    from_bag = _train(tmp_path / 'b', '--bag', str(run_dir))
    assert from_xdf['trials_per_class'] == from_bag['trials_per_class']
    assert from_xdf['n_trials'] == from_bag['n_trials'] == TRIALS
    # one trial is 1/8: windows may sit one sample apart, nothing more
    assert abs(from_xdf['accuracy'] - from_bag['accuracy']) <= 1 / TRIALS, (from_xdf, from_bag)


@pytest.mark.timeout(900)
def test_an_xdf_without_cue_markers_says_so_in_one_line(graz_run: tuple[Path, Path],
                                                        tmp_path: Path) -> None:
    from mindgrasp_testing import write_xdf

    path = tmp_path / 'no_cues.xdf'
    write_xdf(path, np.zeros((500, 3), np.float32), 250.0, 100.0, [(101.0, 'hello')],
              ['C3', 'Cz', 'C4'])
    res = subprocess.run([*MG, 'train', 'classifier', '--xdf', str(path), '-o',
                          str(tmp_path / 'm')], capture_output=True, text=True, timeout=120)
    assert res.returncode == 1 and res.stderr.splitlines() == [
        'mindgrasp train classifier: no_cues.xdf has markers but no cues: expected MIndGrasp '
        'prompt markers (prompt/cue/<class>); for other marker names pass --event-map, e.g. '
        'T1=left_hand,T2=right_hand.']
