"""A replay subject from a subject file: the classifier calibrated on its calibration recordings
(cached by a digest of them), its errors as one line, and one lock-step experiment end to end
whose played recordings include an XDF file (real S001 EEG with string markers)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.player import expand_sources, load_recording
from mindgrasp_experiments.records import read_records
from mindgrasp_experiments.subjects import REPLAY_TAG, replay_model
from mindgrasp_testing import write_graz_xdf, write_recording_xdf

from .test_sweep import mindgrasp

GRAZ_EVENTS = '{rest: rest, left: left_hand, right: right_hand, hands: both_hands, feet: both_feet}'


def graz_subject(folder: Path, *, cal: dict | None = None, extra: str = '',
                 events: str = GRAZ_EVENTS) -> Path:
    """A subject of two small Graz-like XDF sessions of noise (calibration, play)."""
    write_graz_xdf(folder / 'cal.xdf', seed=1, **(cal or {}))
    write_graz_xdf(folder / 'play.xdf', seed=2, **{k: v for k, v in (cal or {}).items()
                                                    if k == 'names'})
    path = folder / 'graz.yaml'
    path.write_text(f'events: {events}\ncalibration: [cal.xdf]\nplay: [play.xdf]\n{extra}')
    return path


def test_the_model_is_calibrated_on_the_calibration_set_and_cached_by_its_digest(
        tmp_path: Path) -> None:
    subject = graz_subject(tmp_path)
    model = replay_model(str(subject), tmp_path / 'out')
    assert model.parent == tmp_path / 'out'
    assert re.fullmatch(rf'graz_classifier_[0-9a-f]{{12}}_{REPLAY_TAG}\.json', model.name), \
        model.name
    provenance = json.loads(model.read_text())['provenance']
    assert provenance['sources'] == [str(tmp_path / 'cal.xdf')]      # never the played file
    assert provenance['trials_per_class'] == {'left_hand': 5, 'right_hand': 5, 'both_hands': 5,
                                              'both_feet': 5, 'rest': 20}
    # one calibration run of 5 trials per class trains a model but cannot be held out: the gate
    # says so and keeps the default pair, instead of refusing the calibration
    gate = json.loads(model.read_text())['gate']
    assert gate['verdict'] == 'needs_training'
    assert gate['reason'].startswith('the calibration is too small to predict the closed loop')
    assert json.loads(model.read_text())['answer_pair']['name'] == 'hands_feet'
    mtime = model.stat().st_mtime_ns
    assert replay_model(str(subject), tmp_path / 'out') == model            # cached
    assert model.stat().st_mtime_ns == mtime
    swapped = graz_subject(tmp_path, events='{rest: rest, left: left_hand, right: right_hand, '
                                            'hands: both_feet, feet: both_hands}')
    assert replay_model(str(swapped), tmp_path / 'out') != model            # another calibration


def test_too_few_calibration_epochs_are_one_line(tmp_path: Path) -> None:
    subject = graz_subject(tmp_path, cal={'trials': 4})
    with pytest.raises(EEGError, match=r"graz\.yaml has too few calibration epochs: \{'left_hand': "
                                       r"4, .*\} \(at least 5 of every class are needed\); give "
                                       'calibration recordings with more trials'):
        replay_model(str(subject), tmp_path / 'out')


def test_recordings_without_motor_channels_need_the_channels_key(tmp_path: Path) -> None:
    names = ('ch1', 'ch2', 'ch3')
    subject = graz_subject(tmp_path, cal={'names': names})
    with pytest.raises(EEGError, match=r'Cannot calibrate the replay subject .*graz\.yaml: Only 0 '
                                       r"motor-strip channels .* \(in a subject file: the "
                                       'channels: key\\)'):
        replay_model(str(subject), tmp_path / 'out')
    subject = graz_subject(tmp_path, cal={'names': names}, extra='channels: all\n')
    model = json.loads(replay_model(str(subject), tmp_path / 'out').read_text())
    assert model['channels'] == list(names)


def run_one_trial(subject: str, out: Path) -> list[str]:
    """``mindgrasp experiment set-locations --subject <subject>``: one trial cut at 12 simulated s
    through the experiment's real nodes (lock-step, in a subprocess), checked; returns the file
    names the classifier was calibrated on."""
    result = mindgrasp('experiment', 'set-locations', '--subject', subject, '--accuracy', '1.0',
                       '--trials', '1', '--seed', '2', '--trial-timeout', '12', '--out',
                       str(out), '--json', '--no-progress')
    assert result.returncode == 0, result.stderr[-3000:]
    s = json.loads(result.stdout.strip().splitlines()[-1])
    assert s['trials'] == 1 and s['node_errors'] == 0
    assert subject in (out / 'params' / 'virtual_amp.yaml').read_text()     # eeg_source
    (record,) = read_records(out)
    assert record.decoder_windows > 0 and 0.0 <= record.online_accuracy <= 1.0
    assert record.subject == subject          # the person, not the virtual subject replaying
    (model,) = out.glob('*_classifier_*.json')
    return [Path(p).name for p in json.loads(model.read_text())['provenance']['sources']]


@pytest.mark.timeout(1800)   # calibration and one whole trial through the real nodes
def test_the_replay_subject_drives_the_experiment_with_real_eeg(tmp_path: Path) -> None:
    """--subject eegmmidb:1: real S001 imagery epochs in the loop, decoded by a model calibrated
    on runs 4 and 6 (never the played runs 8 and 10)."""
    assert run_one_trial('eegmmidb:1', tmp_path / 'replay') == ['S001R04.edf', 'S001R06.edf']


@pytest.mark.slow
@pytest.mark.timeout(1800)   # calibration and one short trial through the real nodes
def test_a_subject_file_with_an_xdf_recording_drives_the_experiment(tmp_path: Path) -> None:
    """--subject subject.yaml: calibration on S001 runs 4 and 6 (EDF through MNE's loader), play
    of run 8 written as XDF with string markers (no durations) and run 10."""
    edf = load_recording(expand_sources(['eegbci:1:8'])[0])
    write_recording_xdf(tmp_path / 'S001R08.xdf', edf.data, edf.rate, edf.channels,
                        [(onset, label) for onset, _duration, label in edf.annotations])
    subject = tmp_path.resolve() / 'S001.yaml'
    hands_feet = '{T0: rest, T1: both_hands, T2: both_feet}'
    subject.write_text(f"""events: {{T0: rest, T1: left_hand, T2: right_hand}}
calibration: [eegbci:1:4, {{file: 'eegbci:1:6', events: {hands_feet}}}]
play: [S001R08.xdf, {{file: 'eegbci:1:10', events: {hands_feet}}}]
""")
    assert run_one_trial(str(subject), tmp_path / 'run') == ['S001R04.edf', 'S001R06.edf']
