# ruff: noqa: N803 - X is scikit-learn's name for the data
"""Offline decoding evaluations in the field's terms (MOABB's): tasks, splits, scores, results.

ROS-free and data-agnostic: it scores covariance *items* grouped into trials
(:class:`Trials`, made by :mod:`mindgrasp_classifier.paradigm`), so one trial may be one epoch
(pyRiemann's pipelines, as MOABB runs them) or the sliding windows of an epoch (MIndGrasp's
decoder, which decides a trial by the mean of its windows' class distances).

Tasks (:data:`TASKS`): which labels a question takes and how they are pooled.

====================  =============================  ======
task                  classes                        chance
====================  =============================  ======
``four_class``        left, right, both hands, feet  0.25
``left_right``        left vs right hand             0.5
``hands_feet``        both hands vs both feet        0.5
``rest_imagery``      rest vs any imagery            0.5
``rest_both_hands``   rest vs both hands             0.5
====================  =============================  ======

Evaluations (one trial never in both the training and the test set of a fold):

- :func:`leave_run_out`: each run held out in turn, the pipeline fitted on the subject's other
  runs. A fold is scored only when its training runs hold every class of the task and its test
  run at least two (EEGMMIDB runs hold two imagery classes each, so a held-out run has only
  two of the four classes).
- :func:`within_session`: MOABB's ``WithinSessionEvaluation`` default, a stratified 5-fold
  (shuffled, seeded) over the session's trials, runs pooled: optimistic when classes and runs
  are confounded (EEGMMIDB's 4-class task), as the training data share the test trials' runs.
- :func:`fit_predict`: calibrated on one set, tested on another (the decodability figures).

Scores: MOABB's metric (:func:`moabb_score`: ROC-AUC for two classes, accuracy above), the mean
over the scored folds as MOABB averages its folds, and the balanced accuracy of the held-out
trials pooled. Result rows carry MOABB's columns (:data:`RESULT_COLUMNS`) plus
:data:`EXTRA_COLUMNS`.
"""

from __future__ import annotations

import csv
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.metrics import accuracy_score, recall_score, roc_auc_score
from sklearn.model_selection import StratifiedKFold

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_common.mi import REST

__all__ = ['EVALUATIONS', 'EXTRA_COLUMNS', 'RESULT_COLUMNS', 'TASKS', 'Recentred', 'Split',
           'Task', 'Trials', 'balanced_accuracy', 'fit_predict', 'leave_run_out', 'moabb_score',
           'task', 'within_session', 'write_results']

#: MOABB's result columns (``moabb.evaluations.base.BaseEvaluation``), in its order
RESULT_COLUMNS = ('score', 'time', 'samples', 'subject', 'session', 'channels', 'n_sessions',
                  'dataset', 'pipeline', 'evaluation')
#: what MIndGrasp's rows add: the task, the metric of ``score``, the pooled balanced accuracy,
#: the folds scored and the trials scored
EXTRA_COLUMNS = ('task', 'metric', 'balanced_accuracy', 'n_folds', 'n_trials')

_LEFT, _RIGHT, _HANDS, _FEET = 0, 1, 2, 3


@dataclass(frozen=True)
class Task:
    """One decoding question.

    Attributes
    ----------
    name, title : str
        Key (``left_right``) and table label (``left vs right hand``).
    labels : tuple of int
        Trial labels taken (0..3, :data:`~mindgrasp_common.mi.REST`).
    groups : mapping int -> int or None
        Label -> class of this task when labels are pooled (rest vs any imagery).
    chance : float
        Accuracy of guessing.
    """

    name: str
    title: str
    labels: tuple[int, ...]
    groups: Mapping[int, int] | None = None
    chance: float = 0.5

    @property
    def classes(self) -> list[int]:
        """The task's classes, sorted."""
        return sorted(set((self.groups or {k: k for k in self.labels}).values()))

    def classes_of(self, labels: np.ndarray) -> np.ndarray:
        """Each label's class in this task, -1 for labels the task does not take."""
        mapping = dict(self.groups or {k: k for k in self.labels})
        return np.array([mapping.get(int(v), -1) for v in np.asarray(labels)], dtype=int)


TASKS: tuple[Task, ...] = (
    Task('four_class', '4 classes', (_LEFT, _RIGHT, _HANDS, _FEET), chance=0.25),
    Task('left_right', 'left vs right hand', (_LEFT, _RIGHT)),
    Task('hands_feet', 'both hands vs both feet', (_HANDS, _FEET)),
    Task('rest_imagery', 'rest vs any imagery', (_LEFT, _RIGHT, _HANDS, _FEET, REST),
         {_LEFT: 1, _RIGHT: 1, _HANDS: 1, _FEET: 1, REST: 0}),
    Task('rest_both_hands', 'rest vs both hands', (_HANDS, REST)),
)
_BY_NAME = {t.name: t for t in TASKS}


def task(name: str) -> Task:
    """The task called ``name`` (:data:`TASKS`)."""
    try:
        return _BY_NAME[name]
    except KeyError:
        msg = f'Unknown task {name!r}; choose from {list(_BY_NAME)}.'
        raise ClassifierError(msg) from None


@dataclass
class Trials:
    """Covariance items of labelled trials (what a paradigm makes of a subject's runs).

    Attributes
    ----------
    covs : ndarray, shape (n_items, n_channels, n_channels)
        One matrix per epoch, or per window of an epoch.
    item_trial : ndarray of int, shape (n_items,)
        Trial of each item (0..n_trials-1).
    labels : ndarray of int, shape (n_trials,)
        Class of each trial (0..3, :data:`~mindgrasp_common.mi.REST`).
    runs : ndarray of int, shape (n_trials,)
        Run (recording) of each trial.
    channels : list of str
    """

    covs: np.ndarray
    item_trial: np.ndarray
    labels: np.ndarray
    runs: np.ndarray
    channels: list[str] = field(default_factory=list)

    @property
    def n_trials(self) -> int:
        """Trials."""
        return len(self.labels)


@dataclass
class Split:
    """Held-out trials of one fold and the pipeline's scores for them.

    Attributes
    ----------
    classes : list of int
        The task's classes, the columns of ``scores``.
    y_true : ndarray of int, shape (n_test,)
    scores : ndarray, shape (n_test, n_classes)
        Higher is more likely (mean over a trial's items).
    seconds : float
        Fitting and predicting time.
    """

    classes: list[int]
    y_true: np.ndarray
    scores: np.ndarray
    seconds: float

    @property
    def y_pred(self) -> np.ndarray:
        """Predicted class of each held-out trial."""
        return np.asarray(self.classes)[np.argmax(self.scores, axis=1)]


class Recentred(ClassifierMixin, BaseEstimator):
    """A covariance classifier on matrices re-centred on the training set's Riemannian mean,
    as MIndGrasp's decoder is trained (``R^{-1/2} C R^{-1/2}``, Zanini et al. 2018).

    Parameters
    ----------
    classifier : estimator
        A :mod:`mindgrasp_classifier.pipelines` classifier (with ``distances``) or any
        scikit-learn classifier on SPD matrices.
    """

    def __init__(self, classifier: Any) -> None:
        self.classifier = classifier

    def fit(self, X: np.ndarray, y: np.ndarray) -> Recentred:
        """Fit the reference and the classifier on ``X``, shape (n, c, c)."""
        from pyriemann.geometry.base import invsqrtm

        from mindgrasp_classifier.pipelines import riemann_mean

        self.white_ = invsqrtm(riemann_mean(X))
        self.classifier_ = clone(self.classifier).fit(self.white_ @ X @ self.white_, y)
        self.classes_ = self.classifier_.classes_
        return self

    def distances(self, X: np.ndarray) -> np.ndarray:
        """The classifier's class distances, shape (n, n_classes)."""
        return self.classifier_.distances(self.white_ @ X @ self.white_)

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """The classifier's probabilities, shape (n, n_classes)."""
        return self.classifier_.predict_proba(self.white_ @ X @ self.white_)

    def predict(self, X: np.ndarray) -> np.ndarray:
        """The classifier's classes, shape (n,)."""
        return self.classifier_.predict(self.white_ @ X @ self.white_)


def _item_scores(fitted: Any, X: np.ndarray) -> np.ndarray:
    """Per-item class scores (higher: more likely): minus the class distances for MIndGrasp's
    classifiers (a trial is decided by its mean distances, as the decoder does), else the
    probabilities."""
    if hasattr(fitted, 'distances'):
        return -np.asarray(fitted.distances(X), dtype=float)
    return np.asarray(fitted.predict_proba(X), dtype=float)


def _trial_means(values: np.ndarray, item_trial: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean of ``values`` rows per trial; returns (trial ids, means)."""
    ids, inverse = np.unique(item_trial, return_inverse=True)
    sums = np.zeros((len(ids), values.shape[1]))
    np.add.at(sums, inverse, values)
    return ids, sums / np.bincount(inverse)[:, None]


def fit_predict(estimator: Any, train: Trials, test: Trials, the_task: Task,
                train_trials: np.ndarray | None = None,
                test_trials: np.ndarray | None = None) -> Split | None:
    """Fit a clone of ``estimator`` on the task's trials of ``train`` and score ``test``'s.

    Parameters
    ----------
    estimator : scikit-learn classifier on SPD matrices
    train, test : Trials
        May be the same object, with ``train_trials`` / ``test_trials`` (bool, shape
        (n_trials,)) choosing the fold's trials.
    the_task : Task

    Returns
    -------
    Split or None
        None when the training trials lack a class of the task (fewer than 2 trials of it) or
        no test trial is of the task.
    """
    y_train = the_task.classes_of(train.labels)
    y_test = the_task.classes_of(test.labels)
    tr = (y_train >= 0) if train_trials is None else (y_train >= 0) & train_trials
    te = (y_test >= 0) if test_trials is None else (y_test >= 0) & test_trials
    classes = the_task.classes
    if not te.any() or any(np.sum(y_train[tr] == k) < 2 for k in classes):
        return None
    started = time.perf_counter()
    items = tr[train.item_trial]
    fitted = clone(estimator).fit(train.covs[items], y_train[train.item_trial[items]])
    test_items = te[test.item_trial]
    ids, scores = _trial_means(_item_scores(fitted, test.covs[test_items]),
                               test.item_trial[test_items])
    order = [list(fitted.classes_).index(k) for k in classes]
    return Split(classes, y_test[ids], scores[:, order], time.perf_counter() - started)


def balanced_accuracy(y_true: np.ndarray, y_pred: np.ndarray) -> float:
    """Mean recall over the classes present in ``y_true``; shapes (n,)."""
    return float(recall_score(y_true, y_pred, labels=np.unique(y_true), average='macro'))


def moabb_score(split: Split) -> tuple[str, float]:
    """MOABB's metric of a fold (``MotorImagery.scoring``): ROC-AUC with two classes (NaN if the
    test trials hold one), accuracy above."""
    if len(split.classes) == 2:
        if len(np.unique(split.y_true)) < 2:
            return 'roc_auc', math.nan
        margin = split.scores[:, 1] - split.scores[:, 0]
        return 'roc_auc', float(roc_auc_score(split.y_true == split.classes[1], margin))
    return 'accuracy', float(accuracy_score(split.y_true, split.y_pred))


def _summary(splits: Sequence[Split | None], the_task: Task) -> dict[str, Any]:
    """Row figures of an evaluation's folds (``score`` NaN when no fold could be scored)."""
    metric = 'roc_auc' if len(the_task.classes) == 2 else 'accuracy'
    done = [s for s in splits if s is not None and len(np.unique(s.y_true)) >= 2]
    fold_scores = [v for v in (moabb_score(s)[1] for s in done) if math.isfinite(v)]
    if not done:
        return {'score': math.nan, 'time': math.nan, 'samples': 0, 'metric': metric,
                'balanced_accuracy': math.nan, 'n_folds': 0, 'n_trials': 0}
    y_true = np.concatenate([s.y_true for s in done])
    y_pred = np.concatenate([s.y_pred for s in done])
    return {'score': float(np.mean(fold_scores)) if fold_scores else math.nan,
            'time': float(np.mean([s.seconds for s in done])), 'samples': len(y_true),
            'metric': metric, 'balanced_accuracy': balanced_accuracy(y_true, y_pred),
            'n_folds': len(done), 'n_trials': len(y_true)}


def leave_run_out(estimator: Any, trials: Trials, the_task: Task) -> dict[str, Any]:
    """Leave-one-run-out figures of ``estimator`` on ``trials`` (see the module docstring).

    Returns
    -------
    dict
        ``score`` (MOABB's metric, mean over the scored folds), ``time`` (s per fold),
        ``samples`` and ``n_trials`` (held-out trials scored), ``metric``,
        ``balanced_accuracy`` (pooled), ``n_folds`` (folds scored).
    """
    splits = []
    for run in np.unique(trials.runs):
        held = trials.runs == run
        splits.append(fit_predict(estimator, trials, trials, the_task, ~held, held))
    return _summary(splits, the_task)


def within_session(estimator: Any, trials: Trials, the_task: Task, *, folds: int = 5,
                   seed: int = 42) -> dict[str, Any]:
    """MOABB's within-session figures: stratified ``folds``-fold over the task's trials,
    shuffled with ``seed`` (fewer folds when a class has fewer trials); keys as
    :func:`leave_run_out`."""
    y = the_task.classes_of(trials.labels)
    idx = np.flatnonzero(y >= 0)
    counts = [int(np.sum(y[idx] == k)) for k in the_task.classes]
    n_folds = min(folds, min(counts))
    if n_folds < 2:
        return _summary([], the_task)
    splits = []
    cv = StratifiedKFold(n_splits=n_folds, shuffle=True, random_state=seed)
    for train_pos, test_pos in cv.split(idx, y[idx]):
        tr = np.zeros(trials.n_trials, dtype=bool)
        te = np.zeros(trials.n_trials, dtype=bool)
        tr[idx[train_pos]] = True
        te[idx[test_pos]] = True
        splits.append(fit_predict(estimator, trials, trials, the_task, tr, te))
    return _summary(splits, the_task)


#: the evaluations by their name in result rows (MOABB's class names where MOABB has one)
EVALUATIONS: dict[str, Callable[..., dict[str, Any]]] = {
    'LeaveOneRunOut': leave_run_out,
    'WithinSession': within_session,
}


def write_results(rows: Sequence[Mapping[str, Any]], path: str | Path) -> Path:
    """Write result rows as CSV with :data:`RESULT_COLUMNS` then :data:`EXTRA_COLUMNS`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open('w', newline='', encoding='utf-8') as f:
        writer = csv.DictWriter(f, fieldnames=[*RESULT_COLUMNS, *EXTRA_COLUMNS],
                                extrasaction='ignore', lineterminator='\n')
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f'{v:.6g}' if isinstance(v, float) else v)
                             for k, v in row.items()})
    return path
