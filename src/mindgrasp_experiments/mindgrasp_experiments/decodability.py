"""How decodable a subject's motor imagery is: the same figures for real and virtual subjects.

A subject's *decodability figures* are offline accuracies of classifiers calibrated on one set of
recordings and tested on another (another run or session), for five questions:

====================  =============================  ======
figure                classes                        chance
====================  =============================  ======
``four_class``        left, right, both hands, feet  0.25
``left_right``        left vs right hand             0.5
``hands_feet``        both hands vs both feet        0.5
``rest_imagery``      rest vs any imagery            0.5
``rest_both_hands``   rest vs both hands             0.5
====================  =============================  ======

They are measured the same way for any source (:func:`measure`): each recording is band-passed
(8-30 Hz, causal 4th-order Butterworth, as the online decoder), cut into one epoch per cue
(0.5-2.5 s after it), each epoch gives an OAS covariance, and the covariances of a recording are
re-centred on their Riemannian mean (unsupervised, per recording: what makes calibration and test
runs comparable). Two pyRiemann classifiers are fitted on the calibration epochs and scored on the
test epochs: MDM and tangent space + logistic regression (``ts_lr``, classes weighted equally).
A figure is a balanced accuracy (mean recall over its classes: rest epochs outnumber each imagery
class, and guessing "rest" must not score), and its score the mean of the two classifiers. Rest
epochs carry the label ``mindgrasp_common.mi.REST`` (4), the decoder's rest class.
These are per-trial figures (one 2-s epoch per cue), not the online decoder's sliding-window
figures of :mod:`mindgrasp_classifier.training`; both subjects are measured alike, which is what
matters here.

Sources:

- a replay subject (:func:`replay_figures`): its calibration and play recordings
  (:mod:`~mindgrasp_eeg.subject_file`), labelled by their event maps;
- the virtual subject (:func:`synthetic_figures`): :class:`~mindgrasp_eeg.synthetic.SyntheticEEG`
  runs that follow the cue schedules of a template (the replay subject's recordings, so both are
  measured on the same protocol, or :func:`eegmmidb_like_schedules`), one generator and one
  seed per run so ``nonstationarity`` changes the conditions between runs; averaged over a few
  repetitions with other seeds.

:func:`fit_virtual` searches the virtual subject's ``separability``, ``lateral_separability``,
``rest_separability`` and ``nonstationarity`` (:class:`~mindgrasp_eeg.synthetic.SyntheticEEG`)
so that its figures match a real subject's (``mindgrasp eeg fit-virtual``). A real subject's
figures rest on few trials (EEGMMIDB: 7-8 per class and run), so each has a sampling error of
5-12 points (:meth:`Decodability.standard_error`): a fit closer than that is fitting chance.
ROS-free.

    >>> cal, test = eegmmidb_like_schedules(seed=0)                    # doctest: +SKIP
    >>> synthetic_figures(cal, test, separability=0.5).scores()         # doctest: +SKIP
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from mindgrasp_common.mi import REST
from mindgrasp_common.types import Recording
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import (
    BOTH_FEET,
    BOTH_HANDS,
    LEFT_HAND,
    NAUTILUS_32,
    NAUTILUS_RATE,
    RIGHT_HAND,
)

__all__ = ['DEFAULT_SETTINGS', 'FIGURES', 'FIT_START', 'PARAMETER_BOUNDS', 'PIPELINES', 'REST',
           'Decodability', 'Figure', 'FitResult', 'MeasureConfig', 'RunSchedule', 'average',
           'common_channels', 'default_jobs', 'eegmmidb_like_schedules', 'epoch_covariances',
           'fit_virtual', 'labelled', 'measure', 'replay_figures', 'replay_recordings',
           'score_errors', 'synthetic_figures', 'synthetic_runs']

#: classifiers of every figure: pyRiemann MDM, tangent space + logistic regression
PIPELINES = ('mdm', 'ts_lr')
#: longest imagery of a cue without a following cue (s); EEGMMIDB cues last 4.1 s
MAX_IMAGERY_S = 4.1
#: the virtual subject's settings that :func:`fit_virtual` searches, and their ranges
PARAMETER_BOUNDS: dict[str, tuple[float, float]] = {
    'separability': (0.0, 2.0),
    'lateral_separability': (0.0, 1.0),
    'rest_separability': (0.0, 2.0),
    'nonstationarity': (0.0, 3.0),
}
_NAMES = tuple(PARAMETER_BOUNDS)
#: the settings of the original virtual subject (SyntheticEEG's defaults)
DEFAULT_SETTINGS: dict[str, float] = {'separability': 1.0, 'lateral_separability': 1.0,
                                      'rest_separability': 0.0, 'nonstationarity': 0.0}
#: where :func:`fit_virtual` starts: a subject with a plain, moderately variable signature
FIT_START: dict[str, float] = {'separability': 1.0, 'lateral_separability': 0.5,
                               'rest_separability': 0.3, 'nonstationarity': 1.0}


@dataclass(frozen=True)
class Figure:
    """One decodability question.

    Attributes
    ----------
    name, title : str
        Key (``left_right``) and table label (``left vs right hand``).
    labels : tuple of int
        Epoch labels taken (0..3, :data:`REST`).
    groups : mapping int -> int or None
        Label -> class of this figure when labels are pooled (rest vs any imagery).
    chance : float
        Accuracy of guessing.
    """

    name: str
    title: str
    labels: tuple[int, ...]
    groups: Mapping[int, int] | None = None
    chance: float = 0.5


FIGURES: tuple[Figure, ...] = (
    Figure('four_class', '4 classes', (LEFT_HAND, RIGHT_HAND, BOTH_HANDS, BOTH_FEET), chance=0.25),
    Figure('left_right', 'left vs right hand', (LEFT_HAND, RIGHT_HAND)),
    Figure('hands_feet', 'both hands vs both feet', (BOTH_HANDS, BOTH_FEET)),
    Figure('rest_imagery', 'rest vs any imagery',
           (LEFT_HAND, RIGHT_HAND, BOTH_HANDS, BOTH_FEET, REST),
           {LEFT_HAND: 1, RIGHT_HAND: 1, BOTH_HANDS: 1, BOTH_FEET: 1, REST: 0}),
    Figure('rest_both_hands', 'rest vs both hands', (BOTH_HANDS, REST)),
)
_FIGURE_NAMES = tuple(f.name for f in FIGURES)


@dataclass(frozen=True)
class MeasureConfig:
    """Preprocessing of :func:`measure` (times in s after the cue, frequencies in Hz).

    Attributes
    ----------
    band : (float, float)
        Band-pass edges.
    filter_order : int
        Butterworth order.
    tmin, tmax : float
        Epoch after each cue.
    pipelines : tuple of str
        Classifiers (:data:`PIPELINES`).
    """

    band: tuple[float, float] = (8.0, 30.0)
    filter_order: int = 4
    tmin: float = 0.5
    tmax: float = 2.5
    pipelines: tuple[str, ...] = PIPELINES


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


# --------------------------------------------------------------------------- epochs
def labelled(recording: Recording, events: Mapping[str, int | None]) -> Recording:
    """A copy of ``recording`` whose ``events`` are its annotations in ``events`` (annotation ->
    class 0..3, None = rest), rest as :data:`REST`; epochs as the replay subject cuts them
    (:func:`~mindgrasp_eeg.replay_eeg.segments`)."""
    from mindgrasp_eeg.replay_eeg import segments

    rows = [(k0, REST if cls is None else int(cls)) for k0, _k1, cls in segments(recording, events)]
    return replace(recording, events=np.array(rows, dtype=int).reshape(-1, 2))


def common_channels(channels: Sequence[str]) -> list[str]:
    """The virtual amplifier's channels (:data:`~mindgrasp_eeg.montage.NAUTILUS_32`) that
    ``channels`` has, in that order, spelled as in ``channels``: both subjects are measured on
    the same electrodes.

    Raises
    ------
    EEGError
        Fewer than 8 of them, or C3, Cz or C4 missing.
    """
    lower = {c.lower(): c for c in channels}
    out = [lower[c.lower()] for c in NAUTILUS_32 if c.lower() in lower]
    missing = [c for c in ('C3', 'Cz', 'C4') if c.lower() not in lower]
    if missing or len(out) < 8:
        msg = (f'The recordings share only {len(out)} channels with the virtual amplifier '
               f'({out}; missing motor channels: {missing}); decodability needs C3, Cz, C4 and '
               f'at least 8 of {list(NAUTILUS_32)}.')
        raise EEGError(msg)
    return out


def epoch_covariances(recording: Recording, channels: Sequence[str],
                      config: MeasureConfig | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Re-centred OAS covariances of the labelled epochs of one recording.

    Parameters
    ----------
    recording : Recording
        Volts; ``events`` rows ``(onset sample, label 0..3 or REST)``.
    channels : sequence of str
        Channels used (names of ``recording.channels``).
    config : MeasureConfig

    Returns
    -------
    covs : ndarray, shape (n_epochs, n_channels, n_channels)
        Whitened by the recording's Riemannian mean (dimensionless; their mean is identity).
    labels : ndarray of int, shape (n_epochs,)
    """
    from pyriemann.geometry.base import invsqrtm
    from pyriemann.geometry.mean import mean_logeuclid, mean_riemann

    from mindgrasp_classifier.errors import ClassifierError
    from mindgrasp_classifier.preprocessing import (
        CausalBandpass,
        channel_indices,
        design_bandpass,
        extract_windows,
        oas_covariances,
    )

    cfg = config or MeasureConfig()
    try:
        idx = channel_indices(recording.channels, channels)
        sos = design_bandpass(*cfg.band, recording.rate, cfg.filter_order)
    except ClassifierError as exc:
        raise EEGError(f'{recording.source}: {exc}') from None
    x = np.asarray(recording.data, dtype=float)[:, idx]
    finite = np.isfinite(x).all(axis=1)
    # lost samples would ring through the filter for ever: filter zeros there, drop their epochs
    filtered = CausalBandpass(sos, len(idx)).process(np.where(finite[:, None], x, 0.0))
    bad_before = np.concatenate([[0], np.cumsum(~finite)])
    fs = recording.rate
    k0, k1 = round(cfg.tmin * fs), round(cfg.tmax * fs)
    starts = recording.events[:, 0] + k0
    stops = recording.events[:, 0] + k1
    ok = (starts >= 0) & (stops <= len(x))
    ok[ok] = bad_before[stops[ok]] == bad_before[starts[ok]]
    if ok.sum() < 2:
        return np.zeros((0, len(idx), len(idx))), np.zeros(0, dtype=int)
    covs = oas_covariances(extract_windows(filtered, stops[ok] - 1, k1 - k0))
    # the Riemannian mean, started at the log-Euclidean one: a few iterations instead of ~20
    white = invsqrtm(mean_riemann(covs, tol=1e-6, init=mean_logeuclid(covs)))
    return white @ covs @ white, recording.events[ok, 1].astype(int)


def log_vectors(covs: np.ndarray) -> np.ndarray:
    """Log-Euclidean tangent vectors of SPD matrices: the upper triangle of ``logm(C)``, the
    off-diagonal terms times sqrt(2), so Euclidean distances between vectors are log-Euclidean
    distances between matrices (pyRiemann ``TangentSpace(metric='logeuclid')`` up to the
    reference, which only shifts every vector alike).

    Parameters
    ----------
    covs : ndarray, shape (n_matrices, n_channels, n_channels)

    Returns
    -------
    vectors : ndarray, shape (n_matrices, n_channels * (n_channels + 1) / 2)
    """
    w, v = np.linalg.eigh(covs)
    logs = (v * np.log(w)[:, None, :]) @ np.swapaxes(v, 1, 2)
    n = covs.shape[-1]
    rows, cols = np.triu_indices(n)
    weight = np.where(rows == cols, 1.0, math.sqrt(2.0))
    return logs[:, rows, cols] * weight


def _predict(pipeline: str, x_train: np.ndarray, y_train: np.ndarray,
             x_test: np.ndarray) -> np.ndarray:
    """Classes of ``x_test`` (log vectors) by a classifier fitted on ``x_train``.

    ``mdm``: minimum distance to the class means, log-Euclidean (pyRiemann
    ``MDM(metric='logeuclid')``: means and distances of log matrices). ``ts_lr``: L2 logistic
    regression (C = 1, as mindgrasp_classifier's ts_lr) on the tangent vectors, classes weighted
    equally. The log-Euclidean metric is close to the affine-invariant one on re-centred
    covariances (mean identity) and needs one eigendecomposition per matrix for all figures.
    """
    classes = np.unique(y_train)
    if pipeline == 'mdm':
        means = np.stack([x_train[y_train == c].mean(axis=0) for c in classes])
        dist = np.linalg.norm(x_test[:, None, :] - means[None], axis=2)
        return classes[np.argmin(dist, axis=1)]
    if pipeline == 'ts_lr':
        from sklearn.linear_model import LogisticRegression

        lr = LogisticRegression(max_iter=2000, class_weight='balanced')
        return lr.fit(x_train, y_train).predict(x_test)
    msg = f'Unknown decodability pipeline {pipeline!r}; choose from {list(PIPELINES)}.'
    raise EEGError(msg)


def _select(x: np.ndarray, labels: np.ndarray,
            figure: Figure) -> tuple[np.ndarray, np.ndarray]:
    """The epochs of ``figure`` (rows of ``x``) and their classes in it."""
    keep = np.isin(labels, figure.labels)
    y = labels[keep]
    if figure.groups is not None:
        y = np.array([figure.groups[int(v)] for v in y], dtype=int)
    return x[keep], y


def measure(calibration: Sequence[Recording], test: Sequence[Recording], *,
            channels: Sequence[str] | None = None, config: MeasureConfig | None = None,
            source: str = '') -> Decodability:
    """Decodability figures: classifiers calibrated on ``calibration``, scored on ``test``.

    Parameters
    ----------
    calibration, test : sequence of Recording
        Volts, ``events`` labelled 0..3 and :data:`REST` (:func:`labelled`); one rate each.
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
    from sklearn.metrics import balanced_accuracy_score

    if not calibration or not test:
        msg = 'Decodability needs calibration and test recordings; give both sets.'
        raise EEGError(msg)
    cfg = config or MeasureConfig()
    chans = list(channels) if channels is not None else common_channels(calibration[0].channels)
    with _one_blas_thread():
        sets = []
        for recs in (calibration, test):
            parts = [epoch_covariances(rec, chans, cfg) for rec in recs]
            sets.append((log_vectors(np.concatenate([c for c, _ in parts])),
                         np.concatenate([y for _, y in parts])))
        (v_cal, y_cal), (v_test, y_test) = sets
        accuracy: dict[str, dict[str, float]] = {}
        n_test: dict[str, list[int]] = {}
        for fig in FIGURES:
            x_tr, y_tr = _select(v_cal, y_cal, fig)
            x_te, y_te = _select(v_test, y_test, fig)
            wanted = sorted(set((fig.groups or {k: k for k in fig.labels}).values()))
            n_test[fig.name] = [int(np.sum(y_te == k)) for k in wanted]
            if min(int(np.sum(y_tr == k)) for k in wanted) < 2 or min(n_test[fig.name]) == 0:
                accuracy[fig.name] = dict.fromkeys(cfg.pipelines, math.nan)
                continue
            accuracy[fig.name] = {
                pipe: float(balanced_accuracy_score(y_te, _predict(pipe, x_tr, y_tr, x_te)))
                for pipe in cfg.pipelines}
    return Decodability(accuracy, n_test, source)


def _one_blas_thread() -> Any:
    """Context: BLAS on one thread. Many small eigendecompositions (32 x 32) gain nothing from
    threads, and on a loaded machine OpenBLAS threads that wait for a core made a measurement
    25 times slower."""
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1, user_api='blas')


def average(results: Sequence[Decodability], source: str = '') -> Decodability:
    """Mean figures of several measurements (NaN where any is NaN)."""
    first = results[0]
    acc = {name: {pipe: float(np.mean([r.accuracy[name][pipe] for r in results]))
                  for pipe in first.accuracy[name]} for name in first.accuracy}
    return Decodability(acc, {k: list(v) for k, v in first.n_test.items()},
                        source or first.source, sum(r.repeats for r in results))


# --------------------------------------------------------------------------- replay subject
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


# --------------------------------------------------------------------------- virtual subject
@dataclass(frozen=True)
class RunSchedule:
    """The cues of one run, to be imagined by the virtual subject.

    Attributes
    ----------
    duration : float
        Length of the run (s).
    cues : tuple of (float, int)
        ``(onset s, label)``, label 0..3 (imagined from the onset until the next cue, at most
        :data:`MAX_IMAGERY_S`) or :data:`REST`; sorted by onset.
    """

    duration: float
    cues: tuple[tuple[float, int], ...]

    @classmethod
    def of(cls, recording: Recording) -> RunSchedule:
        """The schedule of a labelled recording (:func:`labelled`)."""
        rows = sorted((int(k) / recording.rate, int(c)) for k, c in recording.events)
        return cls(recording.duration, tuple(rows))


def eegmmidb_like_schedules(seed: int = 0, trials: int = 15, *, cue_s: float = 4.1,
                            rest_s: float = 4.2) -> tuple[list[RunSchedule], list[RunSchedule]]:
    """A Graz-like protocol shaped as EEGMMIDB's imagery runs: calibration and test sessions of
    two runs each (left/right hand, then both hands/feet), ``trials`` cues per run in seeded
    random order, each cue (``cue_s``) after a rest period (``rest_s``, labelled rest)."""
    rng = np.random.default_rng([seed, 3])
    runs = []
    for pair in ((LEFT_HAND, RIGHT_HAND), (BOTH_HANDS, BOTH_FEET)) * 2:
        order = rng.permutation(np.resize(np.array(pair), trials))
        cues: list[tuple[float, int]] = []
        for i, cls in enumerate(order):
            t = i * (cue_s + rest_s)
            cues += [(t, REST), (t + rest_s, int(cls))]
        runs.append(RunSchedule(trials * (cue_s + rest_s) + rest_s, tuple(cues)))
    return runs[:2], runs[2:]


def _run_seed(seed: int, repeat: int, run: int) -> int:
    """Seed of one synthetic run: distinct for every (seed, repetition, run)."""
    return int(np.random.SeedSequence([seed, repeat, run]).generate_state(1)[0])


def synthetic_runs(schedules: Sequence[RunSchedule], *, seed: int = 0, repeat: int = 0,
                   first_run: int = 0, head_seed: int = 0, separability: float = 1.0,
                   lateral_separability: float = 1.0, rest_separability: float = 0.0,
                   nonstationarity: float = 0.0, rate: float = NAUTILUS_RATE,
                   run_normals: Sequence[np.ndarray] | None = None) -> list[Recording]:
    """Virtual-subject EEG of ``schedules``, one :class:`SyntheticEEG` (own run seed) per run.

    ``run_normals`` (one array of shape (RunConditions.N_DRAWS,) per schedule) sets each run's
    random conditions instead of its seed (:class:`~mindgrasp_eeg.synthetic.RunConditions`).

    Returns
    -------
    recordings : list of Recording
        32 channels (:data:`NAUTILUS_32`) at ``rate`` Hz, volts; ``events`` as the schedule
        (:data:`REST` for rest).
    """
    from mindgrasp_eeg.synthetic import SyntheticEEG

    out = []
    for i, sched in enumerate(schedules):
        run_seed = _run_seed(seed, repeat, first_run + i)
        gen = SyntheticEEG(NAUTILUS_32, rate, seed=run_seed, head_seed=head_seed,
                           separability=separability, lateral_separability=lateral_separability,
                           rest_separability=rest_separability, nonstationarity=nonstationarity,
                           run_normals=None if run_normals is None else run_normals[i])
        n_total = round(sched.duration * rate)
        bounds = [round(t * rate) for t, _ in sched.cues] + [n_total]
        parts = [gen.generate(bounds[0], None)]
        for (_t, label), k0, k1 in zip(sched.cues, bounds[:-1], bounds[1:], strict=True):
            hold = k1 - k0 if label == REST else min(k1 - k0, round(MAX_IMAGERY_S * rate))
            parts.append(gen.generate(hold, None if label == REST else label))
            parts.append(gen.generate(k1 - k0 - hold, None))
        rows = [(k, label) for (_t, label), k in zip(sched.cues, bounds[:-1], strict=True)]
        events = np.array(rows, dtype=int).reshape(-1, 2)
        out.append(Recording(data=np.vstack(parts), rate=rate, channels=list(NAUTILUS_32),
                             events=events, source=f'virtual subject run seed {run_seed}'))
    return out


@dataclass(frozen=True)
class _Job:
    calibration: tuple[RunSchedule, ...]
    test: tuple[RunSchedule, ...]
    channels: tuple[str, ...]
    params: tuple[float, ...]       # in the order of PARAMETER_BOUNDS
    seed: int
    repeat: int
    head_seed: int
    rate: float
    run_normals: np.ndarray           # (n_runs, RunConditions.N_DRAWS)


def _measure_job(job: _Job) -> Decodability:
    kw: dict[str, Any] = {'seed': job.seed, 'repeat': job.repeat, 'head_seed': job.head_seed,
                          'rate': job.rate, **dict(zip(_NAMES, job.params, strict=True))}
    n_cal = len(job.calibration)
    with _one_blas_thread():
        cal = synthetic_runs(job.calibration, run_normals=job.run_normals[:n_cal], **kw)
        test = synthetic_runs(job.test, first_run=n_cal, run_normals=job.run_normals[n_cal:],
                              **kw)
    return measure(cal, test, channels=job.channels)


def _jobs_of(calibration: Sequence[RunSchedule], test: Sequence[RunSchedule],
             params: tuple[float, ...], *, seed: int, repeats: int, head_seed: int,
             channels: Sequence[str], rate: float) -> list[_Job]:
    normals = _stratified_normals(seed, repeats, len(calibration) + len(test))
    return [_Job(tuple(calibration), tuple(test), tuple(channels), params, seed, r, head_seed,
                 rate, normals[r]) for r in range(repeats)]


def _stratified_normals(seed: int, repeats: int, n_runs: int) -> np.ndarray:
    """Standard normal draws of the run conditions of ``repeats`` sessions, Latin-hypercube
    stratified over the sessions: a few sessions then cover good and bad runs evenly, and their
    mean is far steadier than with independent draws (run conditions vary figures most).

    Returns
    -------
    z : ndarray, shape (repeats, n_runs, RunConditions.N_DRAWS)
    """
    from scipy.stats import norm, qmc

    from mindgrasp_eeg.synthetic import RunConditions

    n = RunConditions.N_DRAWS
    lhs = qmc.LatinHypercube(d=n_runs * n, seed=np.random.default_rng([seed, 4]))
    return norm.ppf(lhs.random(repeats)).reshape(repeats, n_runs, n)


def _label(params: tuple[float, ...]) -> str:
    return 'virtual subject ({})'.format(', '.join(
        f'{k} {v:g}' for k, v in zip(_NAMES, params, strict=True)))


def synthetic_figures(calibration: Sequence[RunSchedule], test: Sequence[RunSchedule], *,
                      separability: float = 1.0, lateral_separability: float = 1.0,
                      rest_separability: float = 0.0, nonstationarity: float = 0.0,
                      seed: int = 0, repeats: int = 4,
                      head_seed: int = 0, channels: Sequence[str] = NAUTILUS_32,
                      rate: float = NAUTILUS_RATE, jobs: int = 1) -> Decodability:
    """Decodability of the virtual subject, averaged over ``repeats`` sessions.

    Each repetition generates every calibration and test run with its own seed (from ``seed``),
    so the runs differ in noise and, with ``nonstationarity``, in conditions (stratified over
    the repetitions); the same ``seed`` gives the same runs at any setting (common random
    numbers: differences between settings are not noise). ``jobs`` > 1 measures repetitions in
    parallel processes.
    """
    params = (separability, lateral_separability, rest_separability, nonstationarity)
    todo = _jobs_of(calibration, test, params, seed=seed, repeats=repeats, head_seed=head_seed,
                    channels=channels, rate=rate)
    if jobs <= 1 or repeats <= 1:
        return average([_measure_job(j) for j in todo], _label(params))
    with ProcessPoolExecutor(max_workers=min(jobs, repeats)) as pool:
        return average(list(pool.map(_measure_job, todo)), _label(params))


# --------------------------------------------------------------------------- fit
@dataclass
class FitResult:
    """Outcome of :func:`fit_virtual`.

    Attributes
    ----------
    params : dict str -> float
        Fitted settings (keys of :data:`PARAMETER_BOUNDS`).
    real, synthetic : Decodability
        The target's figures and the virtual subject's with ``params`` (the fit's sessions).
    error : float
        Root mean square of the score differences over the figures (fraction).
    max_error : float
        Largest absolute score difference (fraction).
    n_evaluations : int
        Settings measured.
    check : Decodability or None
        The fitted subject on fresh sessions (other seeds): what it gives beyond the sessions
        it was fitted on.
    history : list of (dict, float)
        Every setting measured and its RMS error.
    """

    params: dict[str, float]
    real: Decodability
    synthetic: Decodability
    error: float
    max_error: float
    n_evaluations: int
    check: Decodability | None = None
    history: list[tuple[dict[str, float], float]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-ready content."""
        out = {'params': dict(self.params), 'error': self.error, 'max_error': self.max_error,
               'n_evaluations': self.n_evaluations, 'real': self.real.to_dict(),
               'synthetic': self.synthetic.to_dict(),
               'check': self.check.to_dict() if self.check is not None else None,
               'history': [{**params, 'error': err} for params, err in self.history]}
        if self.check is not None:
            errors = score_errors(self.real, self.check)
            out['check_error'] = _rms_of(np.array(list(errors.values())))
            out['check_max_error'] = float(max(abs(v) for v in errors.values()))
        return out


def score_errors(real: Decodability, synthetic: Decodability) -> dict[str, float]:
    """Synthetic minus real score per figure (fractions), figures measurable in both."""
    r, s = real.scores(), synthetic.scores()
    return {k: s[k] - r[k] for k in r if math.isfinite(r[k]) and math.isfinite(s[k])}


def fit_virtual(real: Decodability, calibration: Sequence[RunSchedule],
                test: Sequence[RunSchedule], *, channels: Sequence[str] = NAUTILUS_32,
                seed: int = 0, repeats: int = 24, iterations: int = 2, head_seed: int = 0,
                start: Mapping[str, float] | None = None, jobs: int = 1, check: bool = True,
                progress: Callable[[int], None] | None = None) -> FitResult:
    """Fit the virtual subject's decodability settings to a subject's figures.

    Damped Gauss-Newton (Levenberg-Marquardt) on the score differences: each iteration measures
    the current setting and one step up (or down) each parameter (a tenth of its range, for
    the slopes), then three damped steps towards the least-squares match, all in one parallel
    batch, and moves to the best setting measured so far. Every setting is measured with the
    same seeds (:func:`synthetic_figures`), so slopes and comparisons are between settings, not
    noise. At most ``1 + 7 * iterations`` settings, plus the check on fresh sessions.

    Parameters
    ----------
    real : Decodability
        The target figures (:func:`replay_figures`).
    calibration, test : sequence of RunSchedule
        The protocol of the virtual sessions (the real subject's, :meth:`RunSchedule.of`).
    channels : sequence of str
        Channels measured (the real subject's :func:`common_channels`).
    seed, repeats, head_seed : int
        Seeds of the virtual sessions and their number per setting; the virtual head.
    iterations : int
        Gauss-Newton iterations (>= 1).
    start : mapping, optional
        First setting (default: :data:`FIT_START`).
    jobs : int
        Parallel processes.
    check : bool
        Measure the fitted setting once more on ``2 * repeats`` sessions of other seeds
        (:attr:`FitResult.check`).
    progress : callable, optional
        Called with the number of settings measured so far after each batch.

    Returns
    -------
    FitResult
        The best setting measured.
    """
    if iterations < 1 or repeats < 1:
        msg = (f'fit_virtual needs iterations >= 1 and repeats >= 1; got iterations '
               f'{iterations}, repeats {repeats}.')
        raise EEGError(msg)
    lo = np.array([PARAMETER_BOUNDS[k][0] for k in _NAMES])
    hi = np.array([PARAMETER_BOUNDS[k][1] for k in _NAMES])
    span = hi - lo
    first = {**FIT_START, **(start or {})}
    x = np.clip(np.array([float(first[k]) for k in _NAMES]), lo, hi)
    figures = [name for name, v in real.scores().items() if math.isfinite(v)]
    target = np.array([real.score(name) for name in figures])
    cache: dict[tuple[float, ...], Decodability] = {}
    history: list[tuple[dict[str, float], float]] = []
    pool = ProcessPoolExecutor(max_workers=jobs) if jobs > 1 else None

    def key_of(v: np.ndarray) -> tuple[float, ...]:
        return tuple(round(float(a), 4) for a in np.clip(v, lo, hi))

    def residual(k: tuple[float, ...]) -> np.ndarray:
        r = np.array([cache[k].score(name) for name in figures]) - target
        return np.nan_to_num(r, nan=1.0)        # a figure the virtual subject lacks: far off

    def measure_all(points: Sequence[np.ndarray]) -> list[tuple[float, ...]]:
        keys = [key_of(v) for v in points]
        new = [k for k in dict.fromkeys(keys) if k not in cache]
        todo = [j for k in new for j in _jobs_of(calibration, test, k, seed=seed,
                                                  repeats=repeats, head_seed=head_seed,
                                                  channels=channels, rate=NAUTILUS_RATE)]
        done = list(pool.map(_measure_job, todo)) if pool else [_measure_job(j) for j in todo]
        for i, k in enumerate(new):
            cache[k] = average(done[i * repeats:(i + 1) * repeats], _label(k))
            history.append((dict(zip(_NAMES, k, strict=True)), _rms_of(residual(k))))
        if progress is not None and new:
            progress(len(cache))
        return keys

    try:
        step = 0.1 * span
        for _ in range(iterations):
            # one-sided slopes, stepping away from a bound
            h = np.where(x + step <= hi, step, -step)
            keys = measure_all([x] + [x + h[i] * np.eye(len(x))[i] for i in range(len(x))])
            r0 = residual(keys[0])
            steps = [k[i] - keys[0][i] for i, k in enumerate(keys[1:])]   # as rounded
            jac = np.stack([(residual(k) - r0) / steps[i] for i, k in enumerate(keys[1:])],
                           axis=1)
            # damped least squares in units of each range (the parameters differ in scale)
            ju = jac * span
            jtj, jtr = ju.T @ ju, ju.T @ r0
            tries = [x - span * np.linalg.solve(jtj + lam * (np.diag(np.diag(jtj)) + 1e-3 *
                                                             np.eye(len(x))), jtr)
                     for lam in (0.03, 0.3, 3.0)]
            measure_all(tries)
            best = min(cache, key=lambda k: _rms_of(residual(k)))
            moved = not np.allclose(best, x)
            x = np.array(best)
            if not moved:           # no better setting: look closer
                step = step / 2
        best = key_of(x)
        fresh = None
        if check:                   # other seeds than every setting of the search saw
            todo = _jobs_of(calibration, test, best, seed=seed + 1_000_003, repeats=2 * repeats,
                            head_seed=head_seed, channels=channels, rate=NAUTILUS_RATE)
            done = list(pool.map(_measure_job, todo)) if pool else [_measure_job(j)
                                                                     for j in todo]
            fresh = average(done, _label(best) + ', fresh sessions')
            if progress is not None:
                progress(len(cache) + 1)
    finally:
        if pool is not None:
            pool.shutdown()
    errors = score_errors(real, cache[best])
    return FitResult(dict(zip(_NAMES, best, strict=True)), real, cache[best],
                     _rms_of(residual(best)),
                     float(max(abs(v) for v in errors.values())) if errors else math.inf,
                     len(cache), fresh, history)


def _rms_of(r: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(r))))


def default_jobs() -> int:
    """Processes for a fit: the CPUs this process may use, at most 4."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:        # not on Linux
        n = os.cpu_count() or 1
    return max(1, min(4, n))
