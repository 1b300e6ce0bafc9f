"""MOABB-style evaluations (mindgrasp_classifier.evaluation / .paradigm): tasks, folds, scores,
result columns; the pipelines' log-Euclidean metric; real EEG of S001 through the paradigm."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_classifier import evaluation as ev
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.pipelines import MdmClassifier, TsLrClassifier
from mindgrasp_common.mi import REST


def separable_trials(n_runs: int = 3, per_class: int = 6, gap: float = 1.0,
                     seed: int = 1234) -> ev.Trials:
    """Runs of left/right trials then runs of hands/feet trials, class c scaling channel c."""
    from pyriemann.datasets import make_matrices

    rng = np.random.RandomState(seed)
    covs, labels, runs = [], [], []
    for r in range(2 * n_runs):
        pair = (0, 1) if r % 2 == 0 else (2, 3)
        for cls in (*pair, REST):
            c = make_matrices(per_class, 4, 'spd', rs=rng) * 0.2 + np.eye(4)
            if cls != REST:
                c[:, cls, cls] += gap
            covs.append(c)
            labels += [cls] * per_class
            runs += [r] * per_class
    labels_a = np.array(labels)
    return ev.Trials(np.concatenate(covs), np.arange(len(labels_a)), labels_a, np.array(runs),
                     ['a', 'b', 'c', 'd'])


def test_eegmmidb_imagery_runs_are_labelled_as_physionet_says() -> None:
    from mindgrasp_classifier.data import EEGMMIDB_RUNS

    for run in (4, 8, 12):                       # imagined left / right fist
        assert EEGMMIDB_RUNS[run] == {'T1': 0, 'T2': 1}, run
    for run in (6, 10, 14):                      # imagined both fists / both feet
        assert EEGMMIDB_RUNS[run] == {'T1': 2, 'T2': 3}, run


def test_tasks_pool_and_name_their_classes() -> None:
    rest = ev.task('rest_imagery')
    assert rest.classes == [0, 1]
    assert rest.classes_of(np.array([0, 3, REST, 7])).tolist() == [1, 1, 0, -1]
    assert ev.task('four_class').classes == [0, 1, 2, 3] and ev.task('four_class').chance == 0.25
    with pytest.raises(ClassifierError, match="Unknown task 'up_down'; choose from"):
        ev.task('up_down')


@pytest.mark.parametrize('name', ['MDM', 'ours'])
def test_leave_run_out_scores_separable_classes_and_skips_folds_it_cannot_train(name) -> None:
    from pyriemann.classification import MDM

    est = MDM() if name == 'MDM' else ev.Recentred(MdmClassifier())
    trials = separable_trials()
    lr = ev.leave_run_out(est, trials, ev.task('left_right'))
    assert lr['metric'] == 'roc_auc' and lr['score'] > 0.95 and lr['balanced_accuracy'] > 0.9
    assert lr['n_folds'] == 3 and lr['n_trials'] == 36       # the left/right runs only
    four = ev.leave_run_out(est, trials, ev.task('four_class'))
    assert four['metric'] == 'accuracy' and four['n_folds'] == 6 and four['score'] > 0.9
    two = trials.runs <= 1                        # one left/right run, one hands/feet run
    one_run = ev.Trials(trials.covs[two], np.arange(two.sum()), trials.labels[two],
                        trials.runs[two])
    # holding out the only hands/feet run leaves no hands/feet to train on: not scored
    assert ev.leave_run_out(est, one_run, ev.task('hands_feet'))['n_folds'] == 0


def test_chance_data_score_near_chance() -> None:
    trials = separable_trials(gap=0.0)
    out = ev.within_session(ev.Recentred(TsLrClassifier()), trials, ev.task('left_right'))
    assert out['n_folds'] == 5 and abs(out['score'] - 0.5) < 0.25


def test_within_session_is_seeded() -> None:
    trials = separable_trials(gap=0.3)
    a, b = (ev.within_session(ev.Recentred(MdmClassifier()), trials, ev.task('hands_feet'),
                              seed=3) for _ in range(2))
    assert {k: v for k, v in a.items() if k != 'time'} == \
        {k: v for k, v in b.items() if k != 'time'}


def test_windows_of_a_trial_decide_together() -> None:
    trials = separable_trials()
    windows = ev.Trials(np.repeat(trials.covs, 3, axis=0), np.repeat(trials.item_trial, 3),
                        trials.labels, trials.runs)
    split = ev.fit_predict(ev.Recentred(MdmClassifier()), windows, windows,
                           ev.task('left_right'), trials.runs != 0, trials.runs == 0)
    assert split is not None and split.scores.shape == (12, 2)
    assert split.y_true.tolist() == [0] * 6 + [1] * 6


def test_results_have_moabb_columns(tmp_path: Path) -> None:
    row = {**ev.leave_run_out(ev.Recentred(MdmClassifier()), separable_trials(),
                              ev.task('left_right')),
           'subject': 1, 'session': '0', 'channels': 4, 'n_sessions': 1,
           'dataset': 'PhysionetMotorImagery', 'pipeline': 'MG MDM',
           'evaluation': 'LeaveOneRunOut', 'task': 'left_right'}
    path = ev.write_results([row], tmp_path / 'results.csv')
    with path.open() as f:
        reader = csv.DictReader(f)
        rows = list(reader)
    assert reader.fieldnames[:10] == ['score', 'time', 'samples', 'subject', 'session',
                                      'channels', 'n_sessions', 'dataset', 'pipeline',
                                      'evaluation']
    assert list(ev.RESULT_COLUMNS) == reader.fieldnames[:10]
    assert float(rows[0]['score']) > 0.95 and rows[0]['metric'] == 'roc_auc'


def test_log_euclidean_pipelines_match_pyriemann() -> None:
    from pyriemann.classification import MDM
    from pyriemann.datasets import make_matrices

    covs = make_matrices(60, 6, 'spd', rs=0)
    y = np.repeat([0, 1, 2], 20)
    covs[y == 1] *= 1.5
    ours = MdmClassifier(metric='logeuclid').fit(covs[:45], y[:45])
    theirs = MDM(metric='logeuclid').fit(covs[:45], y[:45])
    assert np.array_equal(ours.predict(covs[45:]), theirs.predict(covs[45:]))
    np.testing.assert_allclose(ours.distances(covs[45:]), theirs.transform(covs[45:]),
                               rtol=1e-9)
    ts = TsLrClassifier(metric='logeuclid').fit(covs[:45], y[:45])
    assert ts.predict(covs[45:]).shape == (15,)
    with pytest.raises(ClassifierError, match="Unknown metric 'wasserstein'"):
        MdmClassifier(metric='wasserstein').fit(covs, y)
    with pytest.raises(ClassifierError, match='affine-invariant geodesics'):
        ours.update_mean(0, covs[0], 0.1)


@pytest.mark.slow
def test_paradigm_epochs_s001_as_moabb_and_as_the_decoder(eegbci_path) -> None:
    from mindgrasp_classifier.paradigm import (
        MOABB_PHYSIONET,
        decoder_epoching,
        eegmmidb_runs,
        local_runs,
        trials_of,
    )

    assert local_runs(1, [4, 12, 14]) == [4]            # S001 has runs 3-11 here: 12, 14 absent
    recordings, runs = eegmmidb_runs(1, [4, 6, 12])
    assert runs == [4, 6]
    moabb = trials_of(recordings, MOABB_PHYSIONET)
    assert moabb.covs.shape[1:] == (64, 64) and moabb.n_trials == len(moabb.item_trial)
    assert set(moabb.labels.tolist()) == {0, 1, 2, 3, REST}
    ours = trials_of(recordings, decoder_epoching())
    assert ours.covs.shape[1] == len(ours.channels) < 64          # the motor strip
    assert len(ours.item_trial) > 10 * ours.n_trials              # 1 s windows every 1/16 s
    with pytest.raises(ClassifierError, match='none of the imagery runs'):
        eegmmidb_runs(1, [12, 14])
