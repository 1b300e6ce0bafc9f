"""Real EEG: EEGMMIDB S001 through MNE's loader, chronological split (train 4/6, test 8/10)."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_classifier.data import eegbci_files, eegmmidb_run, load_edf, parse_event_map
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.training import TrainingConfig, evaluate, train

pytestmark = pytest.mark.slow


@pytest.fixture(scope='module')
def runs(eegbci_path):
    files = eegbci_files(1, [4, 6, 8, 10], path=eegbci_path)
    return {eegmmidb_run(f)[1]: load_edf(f) for f in files}


def test_runs_are_labelled_by_name(runs):
    assert runs[4].rate == 160.0 and len(runs[4].channels) == 64 and 'C3' in runs[4].channels
    assert set(runs[4].events[:, 1]) == {0, 1} and set(runs[6].events[:, 1]) == {2, 3}
    assert 14 <= len(runs[8].events) <= 16


def test_hands_feet_well_above_chance(runs):
    model, _ = train([runs[6]], TrainingConfig(classes=[2, 3]), cross_validate=False)
    report = evaluate(model, [runs[10]])
    assert report['n_trials'] == 15
    assert report['accuracy'] >= 0.8          # chance 50 %; 93 % at the time of writing


def test_left_right_above_chance(runs):
    model, _ = train([runs[4]], TrainingConfig(pipeline='ts_lr', channels='all', classes=[0, 1],
                                               train_step=0.25), cross_validate=False)
    report = evaluate(model, [runs[8]])
    assert report['accuracy'] >= 0.65         # chance 50 %; 73 % at the time of writing
    assert report['window_accuracy'] >= 0.6


def test_non_eegmmidb_file_needs_event_map(tmp_path, runs):
    import shutil

    other = tmp_path / 'session.edf'
    shutil.copy(runs[4].source, other)
    with pytest.raises(ClassifierError, match='pass --event-map'):
        load_edf(other)
    rec = load_edf(other, {'T1': 0, 'T2': 1})
    assert len(rec.events) == len(runs[4].events)


def test_rest_epochs_from_t0(runs):
    rec = load_edf(runs[4].source, rest=True)
    assert int((rec.events[:, 1] == 4).sum()) == 15 and len(rec.annotations) == 30
    assert rec.annotations[0] == (0.0, 4.2, 'T0') and rec.annotations[1][2] == 'T2'
    np.testing.assert_array_equal(rec.events[rec.events[:, 1] != 4], runs[4].events)
    with pytest.raises(ClassifierError, match='need an event-map entry for its rest annotation'):
        load_edf(runs[4].source, {'T1': 0, 'T2': 1}, rest=True)
    emap = parse_event_map('T0=rest,T1=left_hand,T2=right_hand')
    assert int((load_edf(runs[4].source, emap, rest=True).events[:, 1] == 4).sum()) == 15
