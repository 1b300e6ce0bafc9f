"""Training and offline evaluation of MI models on labelled recordings.

Windows are cut from the causally filtered continuous recording on the online decoder's window
grid (see :mod:`mindgrasp_classifier.decoder`), so offline figures describe the online decoder.
A trial is decided by the smallest mean distance over its windows.

Cross-validation holds out whole recordings (leave one run out) when the training data has
several, because epochs of one run share more than their class (electrode contact, fatigue, the
run's class set); only a single recording is cross-validated by trial-grouped k-fold. The
held-out window predictions calibrate the model's probabilities (temperature scaling,
:mod:`mindgrasp_classifier.calibration`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from sklearn.metrics import confusion_matrix, recall_score
from sklearn.model_selection import LeaveOneGroupOut, StratifiedGroupKFold

from mindgrasp_classifier.calibration import calibration_summary, fit_temperature, label_positions
from mindgrasp_classifier.data import Recording, add_rest_events
from mindgrasp_classifier.decoder import (
    AdaptationConfig,
    CueLabels,
    MiDecoder,
    Prediction,
    decode_windows,
    filter_recording,
    window_covariances,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import DECODER_CLASS_NAMES as CLASS_NAMES
from mindgrasp_classifier.model import MiModel, library_versions
from mindgrasp_classifier.pipelines import PIPELINES, certainty, make_classifier, riemann_mean
from mindgrasp_classifier.preprocessing import (
    select_channels,
    step_samples,
    window_ends,
    window_samples,
)
from mindgrasp_common.mi import REST

#: ``cross_validation['scheme']`` values
LORO, KFOLD = 'leave_one_run_out', 'trial_grouped_kfold'


#: pyRiemann's covariance estimators (``Covariances(estimator=...)``; its list is private)
COVARIANCE_ESTIMATORS = ('corr', 'cov', 'hub', 'lwf', 'mcd', 'oas', 'sch', 'scm', 'stu', 'tyl')


@dataclass
class TrainingConfig:
    """Settings of a model (all times in seconds, frequencies in Hz).

    Attributes
    ----------
    pipeline : str
        ``mdm`` (default), ``fgmdm`` or ``ts_lr``.
    channels : str or list of str
        ``motor`` (default), ``all`` or channel names.
    band : (float, float)
        Band-pass edges, 8-30 Hz by default.
    filter_order : int
    window, step : float
        Window length (1 s) and online step (1/16 s).
    train_step : float
        Step between training windows inside an epoch.
    tmin, tmax : float
        Epoch relative to the cue (0.5 s to 2.5 s).
    estimator : str
        pyRiemann covariance estimator (``oas``).
    classes : list of int or None
        Classes to keep (None: every class in the data); may include 4 (rest).
    rest : bool
        Label rest epochs: recordings without rest events get their EEGMMIDB T0 annotations as
        class 4 (:func:`~mindgrasp_classifier.data.add_rest_events`). Implied when ``classes``
        includes rest.
    cv_folds : int
        Folds of the trial-grouped k-fold (the scheme of a single recording, and the
        optimistic figure when classes and recordings are confounded).
    min_trials : int
        Fewest trials per class to train.
    seed : int
        Seed of the fold shuffling.
    """

    pipeline: str = 'mdm'
    channels: str | list[str] = 'motor'
    band: tuple[float, float] = (8.0, 30.0)
    filter_order: int = 4
    window: float = 1.0
    step: float = 1.0 / 16.0
    train_step: float = 1.0 / 16.0
    tmin: float = 0.5
    tmax: float = 2.5
    estimator: str = 'oas'
    classes: list[int] | None = None
    rest: bool = False
    cv_folds: int = 5
    min_trials: int = 5
    seed: int = 0

    def check(self) -> None:
        """Raise :class:`ClassifierError` on an invalid setting."""
        if self.pipeline not in PIPELINES:
            msg = f'Unknown pipeline {self.pipeline!r}; choose one of {list(PIPELINES)}.'
            raise ClassifierError(msg)
        if self.estimator not in COVARIANCE_ESTIMATORS:
            msg = (f'Unknown covariance estimator {self.estimator!r}; choose one of '
                   f'{list(COVARIANCE_ESTIMATORS)}.')
            raise ClassifierError(msg)
        if self.tmax - self.tmin < self.window:
            msg = (f'The epoch {self.tmin}-{self.tmax} s is shorter than the window '
                   f'({self.window} s); widen the epoch or shorten the window.')
            raise ClassifierError(msg)
        if self.step <= 0 or self.train_step <= 0:
            msg = (f'Window steps must be positive; got step={self.step}, '
                   f'train_step={self.train_step}.')
            raise ClassifierError(msg)
        if self.rest and self.classes is not None and REST not in self.classes:
            msg = (f'Rest epochs are requested but the classes {self.classes} leave rest out; '
                   'add rest to --classes or leave out --rest.')
            raise ClassifierError(msg)


@dataclass
class Windows:
    """Covariances of epoch windows with their trial labels.

    Attributes
    ----------
    covs : ndarray, shape (n_windows, n_channels, n_channels)
    labels : ndarray of int, shape (n_windows,)
    trials : ndarray of int, shape (n_windows,)
        Global trial id of each window.
    ends : ndarray of int, shape (n_windows,)
        Last sample of each window, in its recording.
    trial_labels : ndarray of int, shape (n_trials,)
    trial_groups : ndarray of int, shape (n_trials,)
        Index (in the recordings given) of the recording of each trial.
    session_covs : list of ndarray
        Covariances over each whole recording (``session_step``), for session re-centering.
    """

    covs: np.ndarray
    labels: np.ndarray
    trials: np.ndarray
    ends: np.ndarray
    trial_labels: np.ndarray
    session_covs: list[np.ndarray] = field(default_factory=list)
    trial_groups: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    @property
    def groups(self) -> np.ndarray:
        """Recording index of each window, shape (n_windows,)."""
        return self.trial_groups[self.trials]


def epoch_windows(model: MiModel, recordings: Sequence[Recording], tmin: float, tmax: float,
                  step: float, classes: Sequence[int] | None = None,
                  session_step: float | None = None) -> Windows:
    """Filter each recording, cut windows inside each cue epoch, estimate covariances.

    ``session_step`` (s), when given, also collects covariances over each whole recording (for
    re-centering on a session) in ``session_covs``.
    """
    n_window = window_samples(model.rate, model.window)
    n_step = step_samples(model.rate, step)
    covs, labels, trials, ends_all, trial_labels, trial_groups = [], [], [], [], [], []
    session_covs = []
    for r, rec in enumerate(recordings):
        filtered = filter_recording(model, rec.data, rec.channels, rec.rate)
        finite = np.isfinite(filtered).all(axis=1)
        bad_before = np.concatenate([[0], np.cumsum(~finite)])
        for onset, cls in rec.events:
            if classes is not None and cls not in classes:
                continue
            start = onset + round(tmin * rec.rate)
            stop = min(onset + round(tmax * rec.rate), filtered.shape[0])
            ends = window_ends(start, stop, n_window, n_step)
            ends = ends[bad_before[ends + 1] - bad_before[ends - n_window + 1] == 0]
            if len(ends) == 0:
                continue
            covs.append(window_covariances(model, filtered, ends))
            labels += [int(cls)] * len(ends)
            trials += [len(trial_labels)] * len(ends)
            ends_all.append(ends)
            trial_labels.append(int(cls))
            trial_groups.append(r)
        if session_step is not None:
            ends = window_ends(0, filtered.shape[0], n_window,
                               step_samples(model.rate, session_step))
            ends = ends[bad_before[ends + 1] - bad_before[ends - n_window + 1] == 0]
            session_covs.append(window_covariances(model, filtered, ends))
    n = len(model.channels)
    return Windows(
        covs=np.concatenate(covs) if covs else np.zeros((0, n, n)),
        labels=np.array(labels, dtype=int), trials=np.array(trials, dtype=int),
        ends=np.concatenate(ends_all) if ends_all else np.zeros(0, dtype=int),
        trial_labels=np.array(trial_labels, dtype=int), session_covs=session_covs,
        trial_groups=np.array(trial_groups, dtype=int))


def _check_counts(trial_labels: np.ndarray, min_trials: int) -> list[int]:
    classes, counts = np.unique(trial_labels, return_counts=True)
    table = {CLASS_NAMES[c]: int(n) for c, n in zip(classes, counts, strict=True)}
    if len(classes) < 2:
        msg = (f'Training needs at least two classes; the data have trials of {table or "none"}. '
               'Add recordings with other classes (or check the event map).')
        raise ClassifierError(msg)
    if counts.min() < min_trials:
        msg = (f'Too few trials per class to train: {table} (at least {min_trials} per class are '
               'needed); record more trials or lower --min-trials.')
        raise ClassifierError(msg)
    return [int(c) for c in classes]


def trial_decisions(distances: np.ndarray, trials: np.ndarray,
                    n_trials: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean distance per trial and the position of its smallest class distance.

    Returns (mean_distances (n_trials, n_classes), argmin positions (n_trials,)).
    """
    sums = np.zeros((n_trials, distances.shape[1]))
    np.add.at(sums, trials, distances)
    counts = np.bincount(trials, minlength=n_trials)[:, None]
    mean = sums / np.maximum(counts, 1)
    return mean, np.argmin(mean, axis=1)


def balanced_accuracy(y_true: np.ndarray, y_pred: np.ndarray) -> float:
    """Mean recall over the classes present in ``y_true`` (scikit-learn's balanced accuracy,
    without its warning when ``y_pred`` holds classes ``y_true`` lacks). Shapes (n,)."""
    return float(recall_score(y_true, y_pred, labels=np.unique(y_true), average='macro'))


def _certainty(distances: np.ndarray) -> np.ndarray:
    """Certainty over the classes with a finite distance (a fold may lack some classes)."""
    d = np.asarray(distances, dtype=float)
    if np.isfinite(d).all():
        return certainty(d)
    d = np.where(np.isfinite(d), d, np.nan)
    return np.nanmean(d, axis=-1) - np.nanmin(d, axis=-1)


def score(classes: Sequence[int], distances: np.ndarray, window_labels: np.ndarray,
          trials: np.ndarray, trial_labels: np.ndarray) -> dict[str, Any]:
    """Accuracy figures of window distances against labels.

    Parameters
    ----------
    classes : sequence of int
        Model classes, the column order of ``distances``.
    distances : ndarray, shape (n_windows, n_classes)
        ``inf`` for a class the deciding model did not know (a cross-validation fold).
    window_labels, trials : ndarray of int, shape (n_windows,)
    trial_labels : ndarray of int, shape (n_trials,)

    Returns
    -------
    report : dict
        ``accuracy`` and ``balanced_accuracy`` (per trial), ``window_accuracy``,
        ``window_balanced_accuracy``, ``n_trials``, ``n_windows``, ``confusion`` (rows true,
        columns predicted, order of ``classes``), ``classes`` (names), ``chance``, and
        ``certainty`` per true class (window statistics).
    """
    classes = np.asarray(classes)
    win_pred = classes[np.argmin(distances, axis=1)]
    _, pos = trial_decisions(distances, trials, len(trial_labels))
    trial_pred = classes[pos]
    cert = _certainty(distances)
    cert_stats = {}
    for c in classes:
        sel = cert[window_labels == c]
        if len(sel):
            cert_stats[CLASS_NAMES[c]] = {
                'mean': float(sel.mean()), 'std': float(sel.std()),
                'q25': float(np.quantile(sel, 0.25)), 'median': float(np.median(sel)),
                'q75': float(np.quantile(sel, 0.75)),
                'mean_correct': float(cert[(window_labels == c) & (win_pred == c)].mean())
                if np.any((window_labels == c) & (win_pred == c)) else None,
            }
    return {
        'accuracy': float(np.mean(trial_pred == trial_labels)),
        'balanced_accuracy': balanced_accuracy(trial_labels, trial_pred),
        'window_accuracy': float(np.mean(win_pred == window_labels)),
        'window_balanced_accuracy': balanced_accuracy(window_labels, win_pred),
        'n_trials': len(trial_labels),
        'n_windows': len(window_labels),
        'trials_per_class': {CLASS_NAMES[c]: int(np.sum(trial_labels == c)) for c in classes},
        'confusion': confusion_matrix(trial_labels, trial_pred, labels=classes).tolist(),
        'classes': [CLASS_NAMES[c] for c in classes],
        'chance': float(1.0 / len(classes)),
        'certainty': cert_stats,
    }


def _blank_model(cfg: TrainingConfig, rec: Recording, classes: list[int]) -> MiModel:
    channels = select_channels(rec.channels, cfg.channels)
    n = len(channels)
    return MiModel(classes=classes, channels=channels, rate=rec.rate, band=tuple(cfg.band),
                   filter_order=cfg.filter_order, window=cfg.window, step=cfg.step,
                   pipeline=cfg.pipeline, classifier=make_classifier(cfg.pipeline),
                   reference=np.eye(n), estimator=cfg.estimator)


def _fit(model: MiModel, covs: np.ndarray, labels: np.ndarray) -> None:
    model.reference = riemann_mean(covs)
    model.classifier = make_classifier(model.pipeline)
    model.classifier.fit(MiModel.recenter(covs, model.reference), labels)


def train(recordings: Sequence[Recording], cfg: TrainingConfig | None = None,
          cross_validate: bool = True) -> tuple[MiModel, dict[str, Any]]:
    """Train a model on labelled recordings.

    Returns
    -------
    model : MiModel
        Fitted on all trials; ``model.provenance`` holds the data, settings, cross-validation
        (``cross_validation``: ``scheme``, ``accuracy``, ``balanced_accuracy`` ...) and the
        probability calibration (``calibration``); ``model.temperature`` is fitted on the
        held-out predictions (1.0 without cross-validation).
    report : dict
        Cross-validation figures (:func:`cross_validate_model`, empty when ``cross_validate``
        is False) with ``calibration``
        (:func:`~mindgrasp_classifier.calibration.calibration_summary` plus the scheme its
        predictions came from).
    """
    cfg = cfg or TrainingConfig()
    cfg.check()
    if not recordings:
        msg = 'No recordings to train on; give EEG files or bags.'
        raise ClassifierError(msg)
    rates = {rec.rate for rec in recordings}
    if len(rates) > 1:
        msg = (f'The recordings have different sampling rates {sorted(rates)} Hz; train on '
               'recordings of one rate (resample the others first).')
        raise ClassifierError(msg)
    if cfg.rest or (cfg.classes is not None and REST in cfg.classes):
        recordings = [add_rest_events(rec) for rec in recordings]
    all_events = np.concatenate([rec.events[:, 1] for rec in recordings])
    present = sorted(set(all_events.tolist()))
    wanted = cfg.classes if cfg.classes is not None else present
    model = _blank_model(cfg, recordings[0], sorted(wanted))
    win = epoch_windows(model, recordings, cfg.tmin, cfg.tmax, cfg.train_step, wanted)
    classes = _check_counts(win.trial_labels, cfg.min_trials)
    if cfg.classes is not None and sorted(cfg.classes) != classes:
        missing = sorted(set(cfg.classes) - set(classes))
        msg = (f'The data have no trials of {[CLASS_NAMES[c] for c in missing]}; record them or '
               'drop them from --classes.')
        raise ClassifierError(msg)
    model.classes = classes
    report: dict[str, Any] = {}
    calibration: dict[str, Any] = {'method': 'temperature_scaling', 'temperature': 1.0,
                                   'source': None}
    if cross_validate:
        names = [_short_name(rec.source, i) for i, rec in enumerate(recordings)]
        report, held = cross_validate_model(model, win, names, cfg.cv_folds, cfg.seed)
        logits = model.classifier.logits(held.distances)
        positions = label_positions(classes, held.labels)
        model.temperature = fit_temperature(logits, positions)
        calibration.update(calibration_summary(logits, positions, model.temperature),
                           source=held.scheme)
        report['calibration'] = calibration
    _fit(model, win.covs, win.labels)
    model.provenance = {
        'sources': [rec.source for rec in recordings],
        'trials_per_class': {CLASS_NAMES[c]: int(np.sum(win.trial_labels == c)) for c in classes},
        'n_windows': len(win.labels),
        'config': asdict(cfg),
        'cross_validation': {k: report[k] for k in CV_KEYS if k in report},
        'calibration': calibration,
    }
    model.versions = library_versions()
    return model, report


#: cross-validation figures kept in a model's provenance
CV_KEYS = ('scheme', 'accuracy', 'balanced_accuracy', 'window_accuracy', 'confusion', 'folds',
           'scored_classes', 'confounded', 'confound', 'per_run', 'n_unscored_trials',
           'optimistic')


def _short_name(source: str, index: int) -> str:
    return Path(source).name if source else f'recording {index + 1}'


@dataclass
class WindowPredictions:
    """Scored window predictions: held out by a cross-validation, or of an evaluation.

    Attributes
    ----------
    distances : ndarray, shape (n_windows, n_classes)
        Class distances in the order of the model's classes; in cross-validation, from the fold
        that held each window out, ``inf`` for classes that fold's training data lacked.
    labels : ndarray of int, shape (n_windows,)
        True class of each window.
    scheme : str
        Where they come from: :data:`LORO`, :data:`KFOLD`, ``offline`` or ``pseudo_online``.
    """

    distances: np.ndarray
    labels: np.ndarray
    scheme: str


def _fold_distances(model: MiModel, win: Windows, train_idx: np.ndarray,
                    test_idx: np.ndarray) -> np.ndarray:
    """Distances of the ``test_idx`` windows under a model fitted on the ``train_idx`` windows,
    in the columns of ``model.classes`` (``inf`` for classes the fold's training data lacks)."""
    fold = model.copy()
    known = sorted(set(win.labels[train_idx].tolist()))
    fold.classes = known
    _fit(fold, win.covs[train_idx], win.labels[train_idx])
    out = np.full((len(test_idx), len(model.classes)), np.inf)
    out[:, [model.classes.index(c) for c in known]] = decode_windows(fold, win.covs[test_idx])
    return out


def _subset(win: Windows, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Window trials renumbered 0.. over the windows ``keep`` (bool, shape (n_windows,)), and
    the labels of those trials."""
    old = np.unique(win.trials[keep])
    return np.searchsorted(old, win.trials[keep]), win.trial_labels[old]


def trial_grouped_kfold(model: MiModel, win: Windows, folds: int,
                        seed: int) -> tuple[dict[str, Any], np.ndarray]:
    """Trial-grouped stratified k-fold (windows of a trial stay in one fold).

    Returns the :func:`score` report (with ``scheme`` and ``folds``) and the held-out
    distances, shape (n_windows, n_classes).
    """
    n_folds = int(min(folds, np.bincount(win.trial_labels).max(initial=0),
                      min(np.sum(win.trial_labels == c) for c in model.classes)))
    if n_folds < 2:
        msg = 'Cross-validation needs at least 2 trials per class; record more trials.'
        raise ClassifierError(msg)
    cv = StratifiedGroupKFold(n_splits=n_folds, shuffle=True, random_state=seed)
    distances = np.zeros((len(win.labels), len(model.classes)))
    for train_idx, test_idx in cv.split(win.covs, win.labels, win.trials):
        distances[test_idx] = _fold_distances(model, win, train_idx, test_idx)
    report = score(model.classes, distances, win.labels, win.trials, win.trial_labels)
    report.update(scheme=KFOLD, folds=n_folds)
    return report, distances


def cross_validate_windows(model: MiModel, win: Windows, folds: int, seed: int) -> dict[str, Any]:
    """Trial-grouped stratified cross-validation report (:func:`trial_grouped_kfold`)."""
    return trial_grouped_kfold(model, win, folds, seed)[0]


def confound_sentence(classes: Sequence[int], run_classes: Sequence[set[int]],
                      names: Sequence[str]) -> str | None:
    """One sentence on classes that only some recordings contain, or None if every recording
    has every class.

    ``run_classes[i]`` holds the classes with trials in recording ``names[i]``.
    """
    where: dict[tuple[str, ...], list[str]] = {}
    for c in classes:
        holders = tuple(n for n, have in zip(names, run_classes, strict=True) if c in have)
        if len(holders) < len(names):
            where.setdefault(holders, []).append(CLASS_NAMES[c])
    if not where:
        return None
    parts = '; '.join(f"{', '.join(cls)} only in {', '.join(h)}" for h, cls in where.items())
    return (f'Classes and recordings are confounded ({parts}): a held-out recording is scored '
            'only on the classes the other recordings also contain, and the trial-grouped '
            'k-fold figure is optimistic because its folds share recordings, whose identity '
            'then gives the class away.')


def leave_one_run_out(model: MiModel, win: Windows,
                      names: Sequence[str]) -> tuple[dict[str, Any], np.ndarray, np.ndarray]:
    """Leave-one-recording-out cross-validation.

    Each recording is decoded by a model fitted on the others, on the trials whose class those
    others contain (a fold can only name classes it was trained on).

    Returns
    -------
    report : dict
        Pooled :func:`score` figures of the scored trials (``accuracy`` etc. ``None`` when no
        trial could be scored), ``scheme``, ``folds`` (recordings), ``per_run`` (per held-out
        recording: its classes, the scored ones, accuracies), ``n_unscored_trials``.
    distances : ndarray, shape (n_windows, n_classes)
        Held-out distances (``inf`` for classes a fold lacked; rows of unscored windows too).
    scored : ndarray of bool, shape (n_windows,)
    """
    groups = win.groups
    distances = np.full((len(win.labels), len(model.classes)), np.inf)
    scored = np.zeros(len(win.labels), dtype=bool)
    per_run = []
    for train_idx, test_idx in LeaveOneGroupOut().split(win.covs, win.labels, groups):
        r = int(groups[test_idx[0]])
        test = groups == r
        known = set(win.labels[train_idx].tolist())
        have = sorted(set(win.trial_labels[win.trial_groups == r].tolist()))
        entry: dict[str, Any] = {'recording': names[r], 'classes': [CLASS_NAMES[c] for c in have]}
        sel = test & np.isin(win.labels, sorted(known)) if len(known) >= 2 else np.zeros_like(test)
        entry['scored_classes'] = sorted({CLASS_NAMES[c] for c in win.labels[sel]},
                                         key=CLASS_NAMES.index)
        entry['n_trials'] = len(np.unique(win.trials[sel]))
        if sel.any():
            scored_idx = np.flatnonzero(sel)
            distances[scored_idx] = _fold_distances(model, win, train_idx, scored_idx)
            scored |= sel
            trials, labels = _subset(win, sel)
            fold = score(model.classes, distances[sel], win.labels[sel], trials, labels)
            entry.update({k: fold[k] for k in ('accuracy', 'balanced_accuracy',
                                                'window_accuracy')})
        else:
            entry.update(accuracy=None, balanced_accuracy=None, window_accuracy=None)
        per_run.append(entry)
    n_unscored = len(win.trial_labels) - len(np.unique(win.trials[scored]))
    if scored.any():
        trials, labels = _subset(win, scored)
        report = score(model.classes, distances[scored], win.labels[scored], trials, labels)
        report['scored_classes'] = [CLASS_NAMES[c] for c in np.unique(labels)]
    else:
        report = {'accuracy': None, 'balanced_accuracy': None, 'window_accuracy': None,
                  'window_balanced_accuracy': None, 'n_trials': 0, 'n_windows': 0,
                  'classes': model.class_names, 'chance': 1.0 / len(model.classes),
                  'scored_classes': []}
    report.update(scheme=LORO, folds=len(per_run), per_run=per_run,
                  n_unscored_trials=int(n_unscored))
    return report, distances, scored


def cross_validate_model(model: MiModel, win: Windows, names: Sequence[str], folds: int = 5,
                         seed: int = 0) -> tuple[dict[str, Any], WindowPredictions]:
    """Cross-validate by recording when there are several, else by trial-grouped k-fold.

    With several recordings the report is :func:`leave_one_run_out`'s, plus ``confounded``
    and, when classes and recordings are confounded, ``confound`` (:func:`confound_sentence`)
    and ``optimistic`` (the trial-grouped k-fold over all recordings, labelled optimistic).
    The held-out predictions for calibration come from leave-one-run-out when they cover at
    least two classes, else from the k-fold.
    """
    runs = np.unique(win.trial_groups)
    if len(runs) < 2:
        report, dist = trial_grouped_kfold(model, win, folds, seed)
        return report, WindowPredictions(dist, win.labels, KFOLD)
    report, dist, scored = leave_one_run_out(model, win, names)
    run_classes = [set(win.trial_labels[win.trial_groups == r].tolist()) for r in runs]
    sentence = confound_sentence(model.classes, run_classes, [names[r] for r in runs])
    report['confounded'] = sentence is not None
    held = WindowPredictions(dist[scored], win.labels[scored], LORO)
    if sentence is not None:
        report['confound'] = sentence
        kfold, kdist = trial_grouped_kfold(model, win, folds, seed)
        report['optimistic'] = {k: kfold[k] for k in (
            'scheme', 'folds', 'accuracy', 'balanced_accuracy', 'window_accuracy',
            'window_balanced_accuracy', 'confusion', 'n_trials')}
        if len(np.unique(held.labels)) < 2:
            held = WindowPredictions(kdist, win.labels, KFOLD)
    return report, held


def evaluate(model: MiModel, recordings: Sequence[Recording], tmin: float = 0.5,
             tmax: float = 2.5, recenter: str = 'fixed') -> dict[str, Any]:
    """Score a model on labelled recordings with the online window grid (step = model step).

    ``recenter='session'`` re-centres each recording on the Riemannian mean of all its windows
    (unsupervised re-centering between sessions) instead of the training reference. The report
    is :func:`score`'s with ``calibration`` (NLL and ECE of the window probabilities,
    :func:`~mindgrasp_classifier.calibration.calibration_summary`).
    """
    return evaluate_windows(model, recordings, tmin, tmax, recenter)[0]


def evaluate_windows(model: MiModel, recordings: Sequence[Recording], tmin: float = 0.5,
                     tmax: float = 2.5,
                     recenter: str = 'fixed') -> tuple[dict[str, Any], WindowPredictions]:
    """:func:`evaluate`, also returning the scored windows' predictions (reliability plots)."""
    if recenter not in ('fixed', 'session'):
        msg = f"Unknown re-centering {recenter!r}; choose 'fixed' or 'session'."
        raise ClassifierError(msg)
    dists, labels, trials, trial_labels = [], [], [], []
    skipped = 0
    for rec in recordings:
        skipped += int(np.sum(~np.isin(rec.events[:, 1], model.classes)))
        win = epoch_windows(model, [rec], tmin, tmax, model.step, model.classes,
                            session_step=0.5 if recenter == 'session' else None)
        if len(win.labels) == 0:
            continue
        ref = riemann_mean(win.session_covs[0]) if recenter == 'session' else None
        dists.append(decode_windows(model, win.covs, ref))
        labels.append(win.labels)
        trials.append(win.trials + len(trial_labels))
        trial_labels += win.trial_labels.tolist()
    if not trial_labels:
        msg = (f'No trials of the model classes {model.class_names} in the data; check the files '
               'and the event map.')
        raise ClassifierError(msg)
    windows = WindowPredictions(np.concatenate(dists), np.concatenate(labels), 'offline')
    report = score(model.classes, windows.distances, windows.labels, np.concatenate(trials),
                   np.array(trial_labels))
    report['skipped_trials_other_classes'] = skipped
    report['recenter'] = recenter
    report['calibration'] = calibration_summary(
        model.classifier.logits(windows.distances), label_positions(model.classes, windows.labels),
        model.temperature)
    return report, windows


def stream_recording(model: MiModel, rec: Recording, adaptation: AdaptationConfig | None = None,
                     chunk: float = 1.0 / 32.0, supervised_labels: bool = False,
                     tmin: float = 0.5, tmax: float = 2.5) -> tuple[np.ndarray, np.ndarray]:
    """Stream a recording chunk by chunk through :class:`MiDecoder` (the online path).

    With ``supervised_labels``, the recording's cues label the windows inside their epochs (as
    trainer prompts do online) for supervised adaptation.

    Returns
    -------
    ends : ndarray of int, shape (n_predictions,)
        Last sample of each predicted window (recording index).
    distances : ndarray, shape (n_predictions, n_classes)
    """
    dec = MiDecoder(model, rec.channels, rec.rate, adaptation)
    cues = CueLabels(tmin, tmax)
    onsets = {int(o): int(c) for o, c in rec.events}
    n_chunk = max(1, round(chunk * rec.rate))
    ends, dists = [], []
    for k in range(0, rec.data.shape[0], n_chunk):
        if supervised_labels:
            for o in range(max(k - n_chunk, 0), k):
                if o in onsets:
                    cues.add(o / rec.rate, onsets[o])
            # label of the windows that end inside this chunk
            t_end = (k + n_chunk - 1) / rec.rate
            dec.set_label(cues.label(t_end - model.window, t_end))
        for res in dec.push(rec.data[k:k + n_chunk], k):
            if isinstance(res, Prediction):
                ends.append(res.sample_index)
                dists.append(res.distances)
    return np.array(ends, dtype=int), np.array(dists).reshape(len(ends), len(model.classes))


def score_predictions(model: MiModel, recordings: Sequence[Recording],
                      predictions: Sequence[tuple[np.ndarray, np.ndarray]], tmin: float = 0.5,
                      tmax: float = 2.5) -> dict[str, Any]:
    """Score online predictions (window ends, distances) per recording like :func:`evaluate`.

    Only windows that lie wholly inside a cue epoch count, as offline.
    """
    n_window = window_samples(model.rate, model.window)
    dists, labels, trials, trial_labels = [], [], [], []
    for rec, (ends, dist) in zip(recordings, predictions, strict=True):
        for onset, cls in rec.events:
            if cls not in model.classes:
                continue
            lo = onset + round(tmin * rec.rate) + n_window - 1
            hi = min(onset + round(tmax * rec.rate), rec.data.shape[0])
            sel = (ends >= lo) & (ends < hi)
            if not sel.any():
                continue
            dists.append(dist[sel])
            labels += [int(cls)] * int(sel.sum())
            trials += [len(trial_labels)] * int(sel.sum())
            trial_labels.append(int(cls))
    if not trial_labels:
        msg = 'No predictions fell inside a cue epoch; check timing and the model classes.'
        raise ClassifierError(msg)
    return score(model.classes, np.concatenate(dists), np.array(labels), np.array(trials),
                 np.array(trial_labels))
