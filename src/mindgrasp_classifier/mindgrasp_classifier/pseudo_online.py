"""Pseudo-online evaluation: the decoder scored on every sliding window, as the loop sees them.

Each recording is streamed chunk by chunk through :class:`~mindgrasp_classifier.decoder.MiDecoder`
(:func:`~mindgrasp_classifier.training.stream_recording`: causal filter, online window grid,
``model.step``), the code path of the classifier node. Every predicted window is labelled by the
labelled stretch it lies in wholly (:func:`label_segments`): a file's annotation for each cue (and
rest, when the recording has rest events), else the cue epoch ``[tmin, tmax]``. Windows that
straddle a label change, or lie in a stretch of a class the model does not know (rest for a model
without rest), are left out.

Figures: the trial accuracy (smallest mean distance over the windows of each cue epoch, as
:func:`~mindgrasp_classifier.training.evaluate`), the sliding-window accuracy per class and
balanced, binary decisions (:data:`BINARY_TASKS`) from the probabilities restricted to two
(groups of) classes, and calibration (NLL, ECE).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

import numpy as np
from sklearn.metrics import confusion_matrix, roc_auc_score

from mindgrasp_classifier.calibration import calibration_summary, label_positions
from mindgrasp_classifier.data import Recording
from mindgrasp_classifier.decoder import AdaptationConfig
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import DECODER_CLASS_NAMES, MiModel
from mindgrasp_classifier.preprocessing import window_samples
from mindgrasp_classifier.training import (
    WindowPredictions,
    balanced_accuracy,
    score_predictions,
    stream_recording,
)
from mindgrasp_common.mi import REST, MiClass

#: binary decisions: name -> (group A, group B); a window of a class in A or B is decided A when
#: the summed probability of A's classes is at least that of B's (classes the model lacks drop out)
BINARY_TASKS: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {
    'left_vs_right': ((MiClass.LEFT_HAND,), (MiClass.RIGHT_HAND,)),
    'hands_vs_feet': ((MiClass.BOTH_HANDS,), (MiClass.BOTH_FEET,)),
    'rest_vs_imagery': ((REST,), tuple(int(c) for c in MiClass)),
    'rest_vs_both_hands': ((REST,), (MiClass.BOTH_HANDS,)),
    'rest_vs_both_feet': ((REST,), (MiClass.BOTH_FEET,)),
    # the controller's cancel: both feet against every other class
    'both_feet_vs_others': ((MiClass.BOTH_FEET,), (*(int(c) for c in MiClass
                                                     if c != MiClass.BOTH_FEET), REST)),
}


def label_segments(rec: Recording, tmin: float = 0.5, tmax: float = 2.5) -> np.ndarray:
    """Labelled stretches of a recording, samples ``[start, stop)``.

    An event whose onset starts one of the file's annotations (within a sample) is labelled
    over that annotation's duration; other events (recorded runs, synthetic data) over their
    cue epoch ``[onset + tmin, onset + tmax]`` (s).

    Returns
    -------
    segments : ndarray of int, shape (n_events, 3)
        ``[start, stop, class]``.
    """
    spans = {}
    for onset_s, duration, _ in rec.annotations:
        if duration > 0:
            spans[round(onset_s * rec.rate)] = round((onset_s + duration) * rec.rate)
    out = []
    for onset, cls in rec.events:
        match = next((o for o in (onset, onset - 1, onset + 1) if o in spans), None)
        if match is not None:
            out.append((onset, spans[match], cls))
        else:
            out.append((onset + round(tmin * rec.rate), onset + round(tmax * rec.rate), cls))
    return np.array(out, dtype=int).reshape(-1, 3)


def window_labels(ends: np.ndarray, n_window: int, segments: np.ndarray) -> np.ndarray:
    """Label of each window ending at ``ends`` (samples, shape (n,)) that lies wholly inside one
    of ``segments`` (:func:`label_segments`); -1 for the others."""
    labels = np.full(len(ends), -1, dtype=int)
    starts = ends - n_window + 1
    for start, stop, cls in segments:
        labels[(starts >= start) & (ends < stop)] = cls
    return labels


def binary_scores(classes: Sequence[int], probabilities: np.ndarray,
                  labels: np.ndarray) -> dict[str, dict[str, Any]]:
    """Binary figures of :data:`BINARY_TASKS` from window probabilities.

    Parameters
    ----------
    classes : sequence of int
        Model classes, the column order of ``probabilities``.
    probabilities : ndarray, shape (n_windows, n_classes)
    labels : ndarray of int, shape (n_windows,)

    Returns
    -------
    scores : dict
        Per task the model can decide (it knows a class of each group) and the data has windows
        of both groups: ``accuracy``, ``balanced_accuracy``, ``auc`` (ROC AUC of
        ``p(A) / (p(A) + p(B))``), ``n_windows`` (A, B).
    """
    classes = list(classes)
    out: dict[str, dict[str, Any]] = {}
    for name, groups in BINARY_TASKS.items():
        known = [[c for c in g if c in classes] for g in groups]
        if not all(known):
            continue
        in_a, in_b = np.isin(labels, known[0]), np.isin(labels, known[1])
        if not (in_a.any() and in_b.any()):
            continue
        sel = in_a | in_b
        p_a = probabilities[sel][:, [classes.index(c) for c in known[0]]].sum(axis=1)
        p_b = probabilities[sel][:, [classes.index(c) for c in known[1]]].sum(axis=1)
        truth = in_a[sel]
        decided = p_a >= p_b
        # p(A | A or B); 0.5 where both are 0 (a fold that knows neither cannot happen here)
        share = np.divide(p_a, p_a + p_b, out=np.full_like(p_a, 0.5), where=(p_a + p_b) > 0)
        out[name] = {
            'accuracy': float(np.mean(decided == truth)),
            'balanced_accuracy': balanced_accuracy(truth, decided),
            'auc': float(roc_auc_score(truth, share)),
            'n_windows': [int(in_a.sum()), int(in_b.sum())],
        }
    return out


def _per_class(classes: Sequence[int], confusion: np.ndarray) -> dict[str, float | None]:
    rows = np.asarray(confusion, dtype=float)
    return {DECODER_CLASS_NAMES[c]: (float(rows[i, i] / rows[i].sum()) if rows[i].sum() else None)
            for i, c in enumerate(classes)}


def node_adaptation() -> AdaptationConfig:
    """The classifier node's default adaptation and re-centering (its parameter defaults), so
    a pseudo-online evaluation decodes as the loop does."""
    from mindgrasp_classifier.params import ClassifierParams

    # node parameter -> AdaptationConfig field where the names differ; the others match
    renamed = {'adaptation': 'mode', 'adaptation_rate': 'rate'}
    wanted = {f.name for f in dataclasses.fields(AdaptationConfig)}
    defaults = {renamed.get(f.name, f.name): f.default
                for f in dataclasses.fields(ClassifierParams)}
    return AdaptationConfig(**{k: v for k, v in defaults.items() if k in wanted})


def pseudo_online(model: MiModel, recordings: Sequence[Recording], tmin: float = 0.5,
                  tmax: float = 2.5, chunk: float = 1.0 / 32.0,
                  adaptation: AdaptationConfig | None = None,
                  ) -> tuple[dict[str, Any], WindowPredictions]:
    """Stream each recording through the online decoder and score every labelled window.

    Parameters
    ----------
    model : MiModel
    recordings : sequence of Recording
        With events of the model's classes (rest events too when the model knows rest).
    tmin, tmax : float
        Cue epoch (s) of the trial decisions, and the labelled stretch of events without an
        annotation.
    chunk : float
        Chunk length (s) fed to the decoder.
    adaptation : AdaptationConfig, optional
        Re-centering and class-mean adaptation of the decoder (default: none, the training
        reference; :func:`node_adaptation` gives the classifier node's defaults). Each
        recording starts a fresh decoder (a new session); supervised modes get no labels.

    Returns
    -------
    report : dict
        ``trial`` (:func:`~mindgrasp_classifier.training.score_predictions` with
        ``per_class`` recall), ``window`` (``accuracy``, ``balanced_accuracy``, ``per_class``,
        ``confusion``, ``n_windows``, ``windows_per_class``, ``n_left_out``), ``binary``
        (:func:`binary_scores`), ``calibration``
        (:func:`~mindgrasp_classifier.calibration.calibration_summary`), ``classes``,
        ``n_predictions``.
    windows : WindowPredictions
        The scored windows (``scheme='pseudo_online'``).
    """
    n_window = window_samples(model.rate, model.window)
    streamed = [stream_recording(model, rec, dataclasses.replace(adaptation or AdaptationConfig()),
                                 chunk=chunk) for rec in recordings]
    trial = score_predictions(model, recordings, streamed, tmin, tmax)
    trial['per_class'] = _per_class(model.classes, trial['confusion'])
    dists, labels, n_left_out = [], [], 0
    for rec, (ends, dist) in zip(recordings, streamed, strict=True):
        lab = window_labels(ends, n_window, label_segments(rec, tmin, tmax))
        keep = np.isin(lab, model.classes)
        n_left_out += int(np.sum(~keep))
        dists.append(dist[keep])
        labels.append(lab[keep])
    windows = WindowPredictions(np.concatenate(dists), np.concatenate(labels), 'pseudo_online')
    if len(windows.labels) == 0:
        msg = (f'No streamed window lies inside a labelled stretch of the model classes '
               f'{model.class_names}; check the event map and the model classes.')
        raise ClassifierError(msg)
    classes = np.asarray(model.classes)
    pred = classes[np.argmin(windows.distances, axis=1)]
    confusion = confusion_matrix(windows.labels, pred, labels=classes)
    probabilities = model.probabilities(windows.distances)
    logits = model.classifier.logits(windows.distances)
    cfg = adaptation or AdaptationConfig()
    report = {
        'classes': model.class_names,
        'adaptation': {'mode': cfg.mode, 'recenter': cfg.recenter},
        'n_predictions': int(sum(len(e) for e, _ in streamed)),
        'trial': trial,
        'window': {
            'accuracy': float(np.mean(pred == windows.labels)),
            'balanced_accuracy': balanced_accuracy(windows.labels, pred),
            'per_class': _per_class(model.classes, confusion),
            'confusion': confusion.tolist(),
            'n_windows': len(windows.labels),
            'windows_per_class': {DECODER_CLASS_NAMES[c]: int(np.sum(windows.labels == c))
                                  for c in model.classes},
            'n_left_out': n_left_out,
        },
        'binary': binary_scores(model.classes, probabilities, windows.labels),
        'calibration': calibration_summary(logits, label_positions(model.classes,
                                                                   windows.labels),
                                           model.temperature),
    }
    return report, windows


def format_pseudo_online(report: dict[str, Any]) -> str:
    """Human-readable :func:`pseudo_online` report."""
    names = report['classes']
    trial, win, cal = report['trial'], report['window'], report['calibration']
    width = max(len(n) for n in names) + 2

    def pct(v: float | None) -> str:
        return '   -  ' if v is None else f'{100 * v:5.1f} %'

    ada = report['adaptation']
    lines = [f"Pseudo-online (re-centering {ada['recenter']}, adaptation {ada['mode']}; "
             f"{report['n_predictions']} predictions; {win['n_windows']} windows inside a "
             f"labelled stretch, {win['n_left_out']} left out; {trial['n_trials']} trials):",
             f"  {'':<{width}}{'trial':>9}{'window':>9}",
             f"  {'accuracy':<{width}}{pct(trial['accuracy']):>9}{pct(win['accuracy']):>9}",
             f"  {'balanced':<{width}}{pct(trial['balanced_accuracy']):>9}"
             f"{pct(win['balanced_accuracy']):>9}"]
    for n in names:
        lines.append(f"  {n:<{width}}{pct(trial['per_class'][n]):>9}"
                     f"{pct(win['per_class'][n]):>9}   ({win['windows_per_class'][n]} windows)")
    if report['binary']:
        lines.append('  binary (windows; probabilities of the two groups): accuracy, balanced, AUC')
        for task, b in report['binary'].items():
            lines.append(f"    {task:<20}{pct(b['accuracy'])}  {pct(b['balanced_accuracy'])}  "
                         f"{b['auc']:.3f}   (windows {b['n_windows'][0]} / {b['n_windows'][1]})")
    lines.append(f"  calibration (windows): ECE {100 * cal['ece']:.1f} % at T = "
                 f"{cal['temperature']:.2f} ({100 * cal['ece_uncalibrated']:.1f} % at T = 1), "
                 f"NLL {cal['nll']:.3f} ({cal['nll_uncalibrated']:.3f} at T = 1)")
    return '\n'.join(lines)
