"""Decodability figures: classifiers calibrated on one set of recordings, scored on another.

The tasks are :data:`mindgrasp_classifier.evaluation.TASKS` (here called figures), the split
and its score :func:`mindgrasp_classifier.evaluation.fit_predict` and
:func:`~mindgrasp_classifier.evaluation.balanced_accuracy`, the classifiers those of
:mod:`mindgrasp_classifier.pipelines` with pyRiemann's log-Euclidean metric
(:func:`make_pipeline`): close to the affine-invariant one on re-centred covariances (mean
identity) and one eigendecomposition per matrix.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mindgrasp_classifier.evaluation import TASKS, Task, Trials, balanced_accuracy, fit_predict
from mindgrasp_common.types import Recording
from mindgrasp_eeg import EEGError
from mindgrasp_experiments.decodability.paradigm import (
    PIPELINES,
    MeasureConfig,
    common_channels,
    epoch_covariances,
    labelled,
)

__all__ = ['FIGURES', 'Decodability', 'Figure', 'average', 'make_pipeline', 'measure',
           'one_blas_thread', 'replay_figures', 'replay_recordings']

#: one decodability question (:class:`mindgrasp_classifier.evaluation.Task`)
Figure = Task
#: the five figures, in table order
FIGURES: tuple[Figure, ...] = TASKS
_FIGURE_NAMES = tuple(f.name for f in FIGURES)


@dataclass(frozen=True)
class Decodability:
    """Decodability figures of one subject.

    Attributes
    ----------
    accuracy : dict str -> dict str -> float
        Figure name -> pipeline -> balanced accuracy on the test epochs (NaN: the data have too
        few epochs of a class of that figure).
    n_test : dict str -> list of int
        Test epochs of each class of a figure (for a synthetic average: per repetition).
    source : str
        What was measured.
    repeats : int
        Measurements averaged (synthetic subjects).
    """

    accuracy: dict[str, dict[str, float]]
    n_test: dict[str, list[int]]
    source: str = ''
    repeats: int = 1

    def score(self, figure: str) -> float:
        """Mean accuracy of the pipelines for ``figure`` (NaN when not measurable)."""
        values = [v for v in self.accuracy.get(figure, {}).values() if math.isfinite(v)]
        return float(np.mean(values)) if values else math.nan

    def scores(self) -> dict[str, float]:
        """:meth:`score` of every figure, in the order of :data:`FIGURES`."""
        return {name: self.score(name) for name in _FIGURE_NAMES}

    def standard_error(self, figure: str) -> float:
        """Sampling error of :meth:`score` from the number of test epochs (binomial, each class's
        recall at the score; NaN when not measurable). Repetitions (synthetic) shrink it."""
        p, counts = self.score(figure), [n for n in self.n_test.get(figure, []) if n > 0]
        if not math.isfinite(p) or not counts:
            return math.nan
        var = sum(p * (1 - p) / n for n in counts) / len(counts) ** 2
        return math.sqrt(var / self.repeats)

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-ready content."""
        return {'source': self.source, 'repeats': self.repeats,
                'accuracy': {k: dict(v) for k, v in self.accuracy.items()},
                'score': self.scores(),
                'standard_error': {k: self.standard_error(k) for k in _FIGURE_NAMES},
                'n_test': {k: list(v) for k, v in self.n_test.items()}}


def make_pipeline(name: str) -> Any:
    """The classifier of a decodability pipeline: ``mdm`` is
    :class:`~mindgrasp_classifier.pipelines.MdmClassifier`, ``ts_lr``
    :class:`~mindgrasp_classifier.pipelines.TsLrClassifier` (L2 logistic regression, C = 1,
    classes weighted equally, tangent space at the identity: the covariances are re-centred per
    recording), both with the log-Euclidean metric."""
    from mindgrasp_classifier.pipelines import MdmClassifier, TsLrClassifier

    if name == 'mdm':
        return MdmClassifier(metric='logeuclid')
    if name == 'ts_lr':
        return TsLrClassifier(metric='logeuclid', reference='identity')
    msg = f'Unknown decodability pipeline {name!r}; choose from {list(PIPELINES)}.'
    raise EEGError(msg)


def one_blas_thread() -> Any:
    """Context: BLAS on one thread. Many small eigendecompositions (32 x 32) gain nothing from
    threads, and on a loaded machine OpenBLAS threads that wait for a core made a measurement
    25 times slower."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api='blas')


def _trials(recordings: Sequence[Recording], channels: Sequence[str],
            config: MeasureConfig) -> Trials:
    parts = [epoch_covariances(rec, channels, config) for rec in recordings]
    labels = np.concatenate([y for _, y in parts])
    runs = np.concatenate([np.full(len(y), i) for i, (_, y) in enumerate(parts)]).astype(int)
    return Trials(np.concatenate([c for c, _ in parts]), np.arange(len(labels)), labels, runs,
                  list(channels))


def measure(calibration: Sequence[Recording], test: Sequence[Recording], *,
            channels: Sequence[str] | None = None, config: MeasureConfig | None = None,
            source: str = '') -> Decodability:
    """Decodability figures: classifiers calibrated on ``calibration``, scored on ``test``.

    Parameters
    ----------
    calibration, test : sequence of Recording
        Volts, ``events`` labelled 0..3 and :data:`~mindgrasp_common.mi.REST`
        (:func:`~mindgrasp_experiments.decodability.paradigm.labelled`); one rate each.
    channels : sequence of str, optional
        Channels used (default: :func:`common_channels` of the first calibration recording).
    config : MeasureConfig
    source : str
        Name of what is measured (for reports).

    Returns
    -------
    Decodability
        A figure whose classes have fewer than 2 calibration epochs or no test epoch is NaN.
    """
    if not calibration or not test:
        msg = 'Decodability needs calibration and test recordings; give both sets.'
        raise EEGError(msg)
    cfg = config or MeasureConfig()
    chans = list(channels) if channels is not None else common_channels(calibration[0].channels)
    accuracy: dict[str, dict[str, float]] = {}
    n_test: dict[str, list[int]] = {}
    with one_blas_thread():
        train, held = _trials(calibration, chans, cfg), _trials(test, chans, cfg)
        for fig in FIGURES:
            y_test = fig.classes_of(held.labels)
            n_test[fig.name] = [int(np.sum(y_test == k)) for k in fig.classes]
            splits = {pipe: fit_predict(make_pipeline(pipe), train, held, fig)
                      if min(n_test[fig.name]) > 0 else None for pipe in cfg.pipelines}
            accuracy[fig.name] = {
                pipe: math.nan if split is None else balanced_accuracy(split.y_true,
                                                                       split.y_pred)
                for pipe, split in splits.items()}
    return Decodability(accuracy, n_test, source)


def average(results: Sequence[Decodability], source: str = '') -> Decodability:
    """Mean figures of several measurements (NaN where any is NaN)."""
    first = results[0]
    acc = {name: {pipe: float(np.mean([r.accuracy[name][pipe] for r in results]))
                  for pipe in first.accuracy[name]} for name in first.accuracy}
    return Decodability(acc, {k: list(v) for k, v in first.n_test.items()},
                        source or first.source, sum(r.repeats for r in results))


def replay_recordings(source: str) -> tuple[list[Recording], list[Recording], str]:
    """Labelled calibration and play recordings of a replay subject (``eegmmidb:<n>`` or a
    subject file), and its ``source``; raises :class:`EEGError` for a bad subject."""
    from mindgrasp_eeg.subject_file import replay_subject

    subject = replay_subject(source)
    sets = []
    for which in ('calibration', 'play'):
        files = getattr(subject, which)
        sets.append([labelled(rec, f.events)
                     for f, rec in zip(files, subject.recordings(which), strict=True)])
    return sets[0], sets[1], subject.source


def replay_figures(source: str, config: MeasureConfig | None = None) -> Decodability:
    """Decodability of a replay subject: calibrated on its calibration set, tested on its play
    set (what the virtual amplifier streams), on :func:`common_channels`."""
    cal, test, name = replay_recordings(source)
    return measure(cal, test, config=config, source=name)
