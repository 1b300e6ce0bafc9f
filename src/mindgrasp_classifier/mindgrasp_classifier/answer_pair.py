"""The person's answer pair and decision thresholds, chosen on held-out calibration data.

The scan paradigm asks the person yes/no questions (:mod:`mindgrasp_fsm.grasp_fsm`); which
imagery answers them is that person's (:mod:`mindgrasp_common.answer_pair`). This module chooses
it, with the decision thresholds, from the person's own calibration recordings, never scoring a
window on a decoder that was trained on it:

1. **Held-out streams** (:func:`heldout_streams`). Each calibration recording is held out in
   turn and streamed chunk by chunk through the online decoder
   (:func:`~mindgrasp_classifier.training.stream_recording`, the classifier node's re-centering,
   :func:`~mindgrasp_classifier.pseudo_online.node_adaptation`) of a model trained on the
   other recordings (leave-run-out). A run whose classes no other run has (EEGMMIDB: each run
   holds one pair of classes; a single recording) is held out by halves instead: each half
   streamed through a model trained on the other recordings and the run's other half. Every
   window lying wholly inside a labelled epoch keeps its probabilities.
2. **Decisions** (:func:`simulate_pair`). For each candidate pair the class a person would
   imagine for "yes" and for "no" gives episodes: held-out windows of that class, epochs of one
   held-out stretch in a seeded random order (as the replay subject stitches them), fed as
   :class:`~mindgrasp_common.types.Prediction` to the controller's own
   :class:`mindgrasp_fsm.evidence.Evidence` (its log-ratio, clip and time weighting). The offer
   test (confirm / pass) and the approach test (affirm / cancel) are read off each episode's
   evidence path for a grid of threshold scales; the thresholds are the fastest scale of the
   default set (confirm, pass, affirm, cancel = 3, 3, 3, 5 nat s), never below it, whose rate of
   wrong decisions on the held-out episodes is at most ``target_wrong_rate``.
3. **A trial** (:func:`predict_trials`). The set-locations protocol is modelled from those
   decisions: the arm offers the objects in turn (the target at a uniformly drawn place),
   each offer answered by a drawn held-out episode, a confirmation followed by the approach
   test, a pass or a cancel moving on (a passed target comes back after a sweep), with the
   arm's own times between decisions (:data:`MOTION_S`, measured with the oracle subject) and
   the trial timeout. Monte Carlo over trials gives the expected correct, wrong and no-grasp
   rates and the time per decision.
4. **The choice** (:func:`select`): the pair with the highest predicted correct rate
   (``hands_feet`` kept when within :data:`PREFER_DEFAULT` of the best; when no pair predicts a
   correct grasp, the best held-out separability), among the pairs the subject's play data can
   express when that is known, and of two imagery classes (:data:`REST_PAIRS_CHOSEN`). The gate
   (:mod:`mindgrasp_classifier.gate`) then says whether the person is ready.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mindgrasp_classifier.data import Recording
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_common.answer_pair import DEFAULT_PAIR, NAMED_PAIRS, AnswerPair, answer_pair
from mindgrasp_common.mi import DECODER_CLASS_NAMES, REST

__all__ = ['DEFAULT_THRESHOLDS', 'MOTION_S', 'REST_PAIRS_CHOSEN', 'TARGET_WRONG_RATE',
           'FoldStream', 'PairResult', 'candidate_pairs', 'choose_pair', 'heldout_streams',
           'predict_trials', 'select', 'simulate_pair']

#: the controller's default decision thresholds (nat s), scaled per person
DEFAULT_THRESHOLDS = {'confirm': 3.0, 'pass': 3.0, 'affirm': 3.0, 'cancel': 5.0}
#: scales of :data:`DEFAULT_THRESHOLDS` tried, fastest first. Never below the defaults: held-out
#: calibration runs flatter a person's next session (S004, thresholds halved on a predicted 0 %
#: wrong: 8 wrong grasps in 18 played trials); a person's data may only make them stricter
SCALES = (1.0, 1.17, 1.33, 1.67, 2.0, 2.5, 3.0)
#: default rate of wrong decisions (per offer answered) the thresholds aim at; chosen on
#: EEGMMIDB S001-S004 (src/mindgrasp_classifier/README.md)
TARGET_WRONG_RATE = 0.05
#: a default pair within this much predicted correct rate of the best is kept
PREFER_DEFAULT = 0.03
#: the arm's own times (s) between decisions in the set-locations protocol (oracle subject,
#: lock-step, the shipped arm): turning to and centring the next object with the locks, the
#: initial approach before the go-on is awaited, the final approach + grasp + lift after it, and
#: the return to the start after a cancel
MOTION_S = {'next_offer': 5.0, 'approach': 6.0, 'grasp': 12.0, 'return': 8.0}
#: pairs with rest on one side (``mi_rest``, ``both_hands_rest``, ...) are not chosen
#: automatically: their held-out predictions were far too optimistic for the closed loop
#: (EEGMMIDB replay, 18 trials each: S002 predicted 99.5 % correct / 0 % wrong, played 5 correct,
#: 4 wrong; S003 2 correct, 5 wrong of 9). They stay available by name (the controller's
#: ``answer_pair`` parameter) and are chosen from with ``rest_pairs=True``.
REST_PAIRS_CHOSEN = False
#: fewest trials per class a fold model is trained on
FOLD_MIN_TRIALS = 3
#: objects the set-locations scene offers in one sweep
N_OBJECTS = 9


@dataclass
class FoldStream:
    """One held-out stretch streamed through a decoder that never saw it.

    Attributes
    ----------
    classes : list of int
        The fold model's classes (column order of ``probabilities``).
    probabilities : ndarray, shape (n_windows, n_classes)
        Calibrated class probabilities of the windows inside a labelled epoch.
    labels : ndarray of int, shape (n_windows,)
        The epoch's class (4 rest).
    epochs : ndarray of int, shape (n_windows,)
        Index of the epoch each window lies in (windows of one epoch are consecutive).
    step : float
        Time between windows (s).
    name : str
        Which stretch (``<run> [first|second half]``).
    """

    classes: list[int]
    probabilities: np.ndarray
    labels: np.ndarray
    epochs: np.ndarray
    step: float
    name: str = ''

    def epochs_of(self, cls: int) -> list[np.ndarray]:
        """The probability rows of each epoch of ``cls``, in recording order."""
        sel = self.labels == cls
        ids = self.epochs[sel]
        rows = self.probabilities[sel]
        return [rows[ids == e] for e in np.unique(ids)]


@dataclass
class PairResult:
    """What one candidate pair would give this person (held-out)."""

    pair: AnswerPair
    heldout_accuracy: float = math.nan       # balanced window accuracy, yes vs no groups
    thresholds: dict[str, float] = field(default_factory=dict)
    wrong_rate: float = math.nan             # wrong offer decisions / offers (chosen scale)
    decision_time_s: float = math.nan        # median time to an offer decision (s)
    predicted: dict[str, float] = field(default_factory=dict)   # predict_trials
    n_episodes: int = 0
    reason: str = ''                         # why it was not evaluated ('' = it was)

    def summary(self) -> dict[str, Any]:
        """The model file's ``gate.pairs`` entry."""
        return {'name': self.pair.name, 'yes': self.pair.to_dict()['yes'],
                'no': self.pair.to_dict()['no'],
                'heldout_accuracy': _num(self.heldout_accuracy),
                'decision_time_s': _num(self.decision_time_s),
                'wrong_rate': _num(self.wrong_rate),
                'predicted_correct_rate': _num(self.predicted.get('correct_rate', math.nan)),
                'predicted_wrong_rate': _num(self.predicted.get('wrong_rate', math.nan)),
                'thresholds': dict(self.thresholds), 'reason': self.reason}


def _num(x: float) -> float | None:
    return None if x is None or not math.isfinite(x) else round(float(x), 4)


# ------------------------------------------------------------------------------ held-out data
def crop(rec: Recording, k0: int, k1: int) -> Recording:
    """Samples ``[k0, k1)`` of ``rec`` with the events and annotations inside them."""
    ev = rec.events[(rec.events[:, 0] >= k0) & (rec.events[:, 0] < k1)].copy()
    ev[:, 0] -= k0
    t0, t1 = k0 / rec.rate, k1 / rec.rate
    ann = [(o - t0, d, name) for o, d, name in rec.annotations if t0 <= o < t1]
    return dataclasses.replace(rec, data=rec.data[k0:k1], events=ev, annotations=ann,
                               source=f'{rec.source}[{k0}:{k1}]')


def _halves(rec: Recording) -> tuple[Recording, Recording]:
    """The recording cut at the onset of the event nearest its middle."""
    onsets = np.sort(rec.events[:, 0])
    mid = int(onsets[np.argmin(np.abs(onsets - len(rec.data) // 2))]) if len(onsets) else \
        len(rec.data) // 2
    return crop(rec, 0, mid), crop(rec, mid, len(rec.data))


def heldout_streams(recordings: Sequence[Recording], cfg: Any, *, tmin: float | None = None,
                    tmax: float | None = None, temperature: float | None = None,
                    log: Callable[[str], None] | None = None) -> list[FoldStream]:
    """Stream every calibration recording through a decoder trained without it (see the module
    docstring, step 1).

    Parameters
    ----------
    recordings : sequence of Recording
        Labelled calibration recordings (rest events included), one run each.
    cfg : TrainingConfig
        How the person's model is trained (each fold model is trained the same way on the
        classes its training data have).
    tmin, tmax : float, optional
        Labelled stretch of an event without an annotation (default ``cfg.tmin``/``tmax``).
    temperature : float, optional
        Probability calibration of the fold models: the person's model's (fitted on its own
        held-out predictions), which spares each fold its inner cross-validation; None: each
        fold model is cross-validated and calibrated on its own training runs.

    Returns
    -------
    streams : list of FoldStream
    """
    from mindgrasp_classifier.preprocessing import window_samples
    from mindgrasp_classifier.pseudo_online import label_segments, node_adaptation, window_labels
    from mindgrasp_classifier.training import stream_recording, train

    if not recordings:
        msg = 'Choosing the answer pair needs calibration recordings; give at least one run.'
        raise ClassifierError(msg)
    tmin = cfg.tmin if tmin is None else tmin
    tmax = cfg.tmax if tmax is None else tmax
    wanted = set(cfg.classes) if cfg.classes is not None else None
    folds: list[tuple[str, list[Recording], Recording]] = []
    kinds = [set(r.events[:, 1].tolist()) - {REST} for r in recordings]
    for i, rec in enumerate(recordings):
        others = [r for j, r in enumerate(recordings) if j != i]
        elsewhere = set().union(*(kinds[j] for j in range(len(recordings)) if j != i))
        if kinds[i] <= elsewhere:
            folds.append((f'run {i + 1}', others, rec))
        else:
            first, second = _halves(rec)
            folds.append((f'run {i + 1} first half', [*others, second], first))
            folds.append((f'run {i + 1} second half', [*others, first], second))
    out = []
    for name, train_recs, test in folds:
        present = set(np.concatenate([r.events[:, 1] for r in train_recs]).tolist())
        classes = sorted(present if wanted is None else present & wanted)
        # a run held out by halves leaves half its trials to train on
        fold_cfg = dataclasses.replace(cfg, classes=classes,
                                       min_trials=min(cfg.min_trials, FOLD_MIN_TRIALS))
        try:
            model, _ = train(train_recs, fold_cfg, cross_validate=temperature is None)
        except ClassifierError as exc:
            if log:
                log(f'answer pair: fold {name} skipped ({exc})')
            continue
        if temperature is not None:
            model.temperature = float(temperature)
        ends, dist = stream_recording(model, test, node_adaptation())
        segs = label_segments(test, tmin, tmax)
        labels = window_labels(ends, window_samples(model.rate, model.window), segs)
        epoch = np.full(len(ends), -1, dtype=int)
        starts = ends - window_samples(model.rate, model.window) + 1
        for k, (s0, s1, _c) in enumerate(segs):
            epoch[(starts >= s0) & (ends < s1)] = k
        keep = np.isin(labels, model.classes) & (epoch >= 0)
        out.append(FoldStream(list(model.classes), model.probabilities(dist[keep]),
                              labels[keep], epoch[keep], float(model.step), name))
        if log:
            log(f'answer pair: held out {name}: {int(keep.sum())} windows, classes '
                f'{[DECODER_CLASS_NAMES[c] for c in model.classes]}')
    if not out:
        msg = 'No fold of the calibration could be trained; record more trials of every class.'
        raise ClassifierError(msg)
    return out


# ------------------------------------------------------------------------------ decisions
def candidate_pairs(classes: Sequence[int], play_classes: set[int] | None = None, *,
                    rest_pairs: bool = REST_PAIRS_CHOSEN) -> list[AnswerPair]:
    """Every pair the decoder's ``classes`` allow: the named ones, then each other (yes imagery
    class, no class); with ``play_classes`` (classes the subject's play data hold, rest always
    there) only pairs whose imagined classes are among them. ``mi_rest``'s yes side lists the
    imagery classes the decoder knows, the play data's first. Pairs with rest on a side only
    with ``rest_pairs`` (:data:`REST_PAIRS_CHOSEN`)."""
    known = set(classes) if rest_pairs else set(classes) - {REST}
    can = set(known) if play_classes is None else (set(play_classes) | {REST}) & known
    out: list[AnswerPair] = []
    for name, (yes, no) in NAMED_PAIRS.items():
        if name == 'mi_rest':
            imagery = [c for c in yes if c in known]
            first = [c for c in imagery if c in can]
            if REST in can and first:
                out.append(AnswerPair(name, tuple([*first, *[c for c in imagery
                                                             if c not in first]]), no))
        elif yes[0] in can and no[0] in can:
            out.append(AnswerPair(name, yes, no))
    taken = {(p.yes, p.no) for p in out} | {(tuple(n), tuple(y)) for _nm, (y, n) in
                                             NAMED_PAIRS.items()}
    for y in sorted(can - {REST}):
        for n in sorted(can - {y}):
            if ((y,), (n,)) not in taken:
                out.append(answer_pair(f'{DECODER_CLASS_NAMES[y]}_{DECODER_CLASS_NAMES[n]}'))
    return out


def _pair_accuracy(streams: Sequence[FoldStream], pair: AnswerPair) -> float:
    """Balanced held-out window accuracy of yes (the imagined class) against no."""
    hits = {True: [], False: []}
    for s in streams:
        cls = list(s.classes)
        yes = [cls.index(c) for c in pair.yes if c in cls]
        no = [cls.index(c) for c in pair.no if c in cls]
        if not yes or not no:
            continue
        for side, c in ((True, pair.yes[0]), (False, pair.no[0])):
            rows = s.probabilities[s.labels == c]
            if len(rows):
                said_yes = rows[:, yes].sum(axis=1) >= rows[:, no].sum(axis=1)
                hits[side].extend((said_yes == side).tolist())
    if not hits[True] or not hits[False]:
        return math.nan
    return 0.5 * (float(np.mean(hits[True])) + float(np.mean(hits[False])))


def _episodes(streams: Sequence[FoldStream], pair: AnswerPair, cls: int, n: int,
              n_windows: int, rng: np.random.Generator) -> list[tuple[list[int], np.ndarray]]:
    """``n`` episodes of ``cls`` imagery per stream whose model knows the pair: (the fold's
    classes, probability rows (n_windows, n_classes)), epochs of that stretch stitched in a
    random order."""
    out = []
    for s in streams:
        if not (set(pair.yes) & set(s.classes) and set(pair.no) & set(s.classes)):
            continue
        eps = s.epochs_of(cls)
        if not eps:
            continue
        for _ in range(n):
            rows, total = [], 0
            while total < n_windows:
                for k in rng.permutation(len(eps)):
                    rows.append(eps[k])
                    total += len(eps[k])
                    if total >= n_windows:
                        break
            out.append((s.classes, np.concatenate(rows)[:n_windows]))
    return out


def _path(classes: list[int], rows: np.ndarray, for_class: Any, against: Sequence[int],
          step: float, clip: float) -> np.ndarray:
    """Evidence (nat s) after each window: the controller's :class:`Evidence`, never
    deciding (its thresholds out of reach), so one path serves every threshold."""
    from mindgrasp_common.types import Prediction
    from mindgrasp_fsm.evidence import Evidence

    ev = Evidence(for_class, against, threshold=1e12, clip=clip, reject_threshold=1e12)
    ev.reset(0.0)
    out = np.empty(len(rows))
    cls = tuple(classes)
    for k, p in enumerate(rows):
        ev.update(Prediction(-1, 0.0, stamp=(k + 1) * step, classes=cls, probabilities=p))
        out[k] = ev.value
    return out


def _first(path: np.ndarray, up: float, down: float, limit: int) -> tuple[int, int]:
    """(+1 up / -1 down / 0 none, index) of the first crossing within ``limit`` windows."""
    p = path[:limit]
    hi = np.flatnonzero(p >= up)
    lo = np.flatnonzero(p <= -down)
    a = hi[0] if len(hi) else limit
    b = lo[0] if len(lo) else limit
    if a == b == limit:
        return 0, limit
    return (1, int(a)) if a < b else (-1, int(b))


@dataclass
class _Decisions:
    """Sampled decisions at one threshold scale: outcomes (+1 yes / -1 no / 0 none) and times."""

    offer_yes: list[tuple[int, float]]       # target offers (the person answers yes)
    offer_no: list[tuple[int, float]]        # other offers (no)
    approach_right: list[int]                # +1 grasp, -1 cancelled, 0 no go-on
    approach_wrong: list[int]                # +1 wrong grasp, -1 cancelled, 0 no go-on


def _decide(paths: dict[str, list[np.ndarray]], th: dict[str, float], step: float,
            timing: dict[str, float]) -> _Decisions:
    off = round((timing['offer_timeout'] - timing['offer_delay']) / step)
    go = round((MOTION_S['approach'] + timing['offer_timeout'] - timing['offer_delay'])
                   / step)
    grasp = round(MOTION_S['grasp'] / step)

    def offer(path: np.ndarray) -> tuple[int, float]:
        o, k = _first(path, th['confirm'], th['pass'], off)
        return o, timing['offer_delay'] + (k + 1) * step

    def approach(path: np.ndarray) -> int:
        # the cancel test (for "no" against "yes"): -1 here is the go-on (affirm)
        o, k = _first(path, th['cancel'], th['affirm'], go)
        if o <= 0:
            return 0 if o == 0 else _after_affirm(path, k)
        return -1

    def _after_affirm(path: np.ndarray, k: int) -> int:
        # affirmed: the evidence stays >= -affirm and may still cancel before the gripper closes
        rest = path[k + 1:k + 1 + grasp] - path[k]
        floor = np.minimum.accumulate(np.minimum(rest, 0.0)) if len(rest) else rest
        value = -th['affirm'] + rest - floor if len(rest) else rest
        return -1 if len(value) and np.any(value >= th['cancel']) else 1

    return _Decisions([offer(p) for p in paths['offer_yes']],
                      [offer(p) for p in paths['offer_no']],
                      [approach(p) for p in paths['approach_yes']],
                      [approach(p) for p in paths['approach_no']])


def predict_trials(d: _Decisions, timing: dict[str, float], rng: np.random.Generator,
                   n_trials: int = 400) -> dict[str, float]:
    """The set-locations protocol modelled from sampled decisions (module docstring, step 3).

    Returns
    -------
    dict
        ``correct_rate``, ``wrong_rate``, ``no_grasp_rate`` (per trial), ``trial_time_s``
        (mean time to a correct grasp, s), ``offers_per_trial``.
    """
    if not (d.offer_yes and d.offer_no and d.approach_right and d.approach_wrong):
        return {'correct_rate': math.nan, 'wrong_rate': math.nan, 'no_grasp_rate': math.nan,
                'trial_time_s': math.nan, 'offers_per_trial': math.nan}
    limit = timing['trial_timeout']
    counts = {'correct': 0, 'wrong': 0, 'none': 0}
    times, offers = [], []
    for _ in range(n_trials):
        target = int(rng.integers(N_OBJECTS))
        t, k, n_off, result = 0.0, 0, 0, 'none'
        while t < limit:
            t += MOTION_S['next_offer']
            n_off += 1
            is_target = k % N_OBJECTS == target
            o, dt = (d.offer_yes if is_target else d.offer_no)[
                int(rng.integers(len(d.offer_yes if is_target else d.offer_no)))]
            t += dt if o else timing['offer_timeout']
            k += 1
            if o <= 0:
                continue
            pool = d.approach_right if is_target else d.approach_wrong
            a = pool[int(rng.integers(len(pool)))]
            if a > 0:
                t += MOTION_S['approach'] + MOTION_S['grasp']
                if t <= limit:
                    result = 'correct' if is_target else 'wrong'
                break
            t += MOTION_S['approach'] + MOTION_S['return']
        counts[result] += 1
        offers.append(n_off)
        if result == 'correct':
            times.append(t)
    n = float(n_trials)
    return {'correct_rate': counts['correct'] / n, 'wrong_rate': counts['wrong'] / n,
            'no_grasp_rate': counts['none'] / n,
            'trial_time_s': float(np.mean(times)) if times else math.nan,
            'offers_per_trial': float(np.mean(offers))}


def simulate_pair(streams: Sequence[FoldStream], pair: AnswerPair, *,
                  target_wrong_rate: float = TARGET_WRONG_RATE, clip: float = 2.0,
                  timing: dict[str, float] | None = None, episodes: int = 12,
                  seed: int = 0) -> PairResult:
    """Held-out accuracy, per-person thresholds and predicted trial figures of one pair."""
    timing = {**default_timing(), **(timing or {})}
    rng = np.random.default_rng(seed)
    # only stretches that hold both answers: two classes never recorded in one run (EEGMMIDB:
    # a hand of runs 4/8/12 against both feet of runs 6/10/14) are told apart by the run, not
    # by the imagery (shuffled labels then look separable), so such a pair is not evaluated
    usable = [s for s in streams if set(pair.yes) & set(s.classes) and
              set(pair.no) & set(s.classes) and np.any(s.labels == pair.yes[0]) and
              np.any(s.labels == pair.no[0])]
    res = PairResult(pair, heldout_accuracy=_pair_accuracy(usable, pair))
    if not usable or not math.isfinite(res.heldout_accuracy):
        res.reason = ('no held-out stretch holds both answers (never recorded in one run: '
                      'confounded with the run)')
        return res
    step = usable[0].step
    n_off = math.ceil((timing['offer_timeout'] - timing['offer_delay']) / step)
    n_app = math.ceil((MOTION_S['approach'] + MOTION_S['grasp'] + timing['offer_timeout'])
                          / step)
    yes_c, no_c = pair.yes[0], pair.no[0]
    yes_for = list(pair.yes) if len(pair.yes) > 1 else pair.yes[0]
    no_for = list(pair.no) if len(pair.no) > 1 else pair.no[0]
    paths: dict[str, list[np.ndarray]] = {}
    for key, cls, n_win, for_, against in (
            ('offer_yes', yes_c, n_off, yes_for, pair.no),
            ('offer_no', no_c, n_off, yes_for, pair.no),
            ('approach_yes', yes_c, n_app, no_for, pair.yes),
            ('approach_no', no_c, n_app, no_for, pair.yes)):
        paths[key] = [_path(c, rows, for_, against, step, clip)
                      for c, rows in _episodes(usable, pair, cls, episodes, n_win, rng)]
    if not all(paths.values()):
        res.reason = 'no held-out episodes of both answers'
        return res
    res.n_episodes = len(paths['offer_yes']) + len(paths['offer_no'])
    chosen = None
    for scale in SCALES:
        th = {k: v * scale for k, v in DEFAULT_THRESHOLDS.items()}
        d = _decide(paths, th, step, timing)
        wrong = sum(o < 0 for o, _ in d.offer_yes) + sum(o > 0 for o, _ in d.offer_no)
        rate = wrong / (len(d.offer_yes) + len(d.offer_no))
        chosen = (th, d, rate)
        if rate <= target_wrong_rate:
            break
    assert chosen is not None
    th, d, rate = chosen
    res.thresholds = {k: round(v, 3) for k, v in th.items()}
    res.wrong_rate = rate
    times = [t for o, t in d.offer_yes + d.offer_no if o != 0]
    res.decision_time_s = float(np.median(times)) if times else math.nan
    res.predicted = predict_trials(d, timing, rng)
    if rate > target_wrong_rate:
        res.reason = (f'wrong decisions {100 * rate:.0f} % > {100 * target_wrong_rate:.0f} % '
                      'even at the highest thresholds')
    return res


def default_timing() -> dict[str, float]:
    """The controller's offer timing (FsmParams defaults) and the experiment's trial timeout."""
    from mindgrasp_fsm.params import FsmParams

    p = FsmParams()
    return {'offer_timeout': p.offer_timeout, 'offer_delay': p.offer_delay,
            'trial_timeout': 600.0, 'clip': p.evidence_clip}


def select(results: Sequence[PairResult]) -> PairResult:
    """The chosen pair: the highest predicted correct rate, then held-out accuracy, then the
    fastest decision; the default pair is kept when it predicts within :data:`PREFER_DEFAULT`
    of the best, never when no pair predicts a correct grasp (then separability decides)."""
    def key(r: PairResult) -> tuple[float, float, float]:
        c = r.predicted.get('correct_rate', math.nan)
        return (c if math.isfinite(c) else -1.0,
                r.heldout_accuracy if math.isfinite(r.heldout_accuracy) else -1.0,
                -(r.decision_time_s if math.isfinite(r.decision_time_s) else 1e9))

    best = max(results, key=key)
    default = next((r for r in results if r.pair.name == DEFAULT_PAIR), None)
    if default is not None and key(best)[0] > 0 and \
            key(default)[0] >= key(best)[0] - PREFER_DEFAULT:
        best = default
    return best


def choose_pair(streams: Sequence[FoldStream], *, play_classes: set[int] | None = None,
                rest_pairs: bool = REST_PAIRS_CHOSEN,
                target_wrong_rate: float = TARGET_WRONG_RATE,
                timing: dict[str, float] | None = None, seed: int = 0,
                log: Callable[[str], None] | None = None) -> tuple[PairResult, list[PairResult]]:
    """Evaluate every candidate pair (:func:`candidate_pairs`) and choose one (module
    docstring, step 4). Returns (the chosen pair's result, every candidate's result)."""
    timing = {**default_timing(), **(timing or {})}
    classes = sorted(set().union(*(set(s.classes) for s in streams)))
    results = [simulate_pair(streams, p, target_wrong_rate=target_wrong_rate,
                             clip=timing['clip'], timing=timing, seed=seed)
               for p in candidate_pairs(classes, play_classes, rest_pairs=rest_pairs)]
    if not results:
        msg = ('No answer pair is possible: the decoder and the play data share no two classes; '
               'calibrate on runs with the classes the person will use.')
        raise ClassifierError(msg)

    best = select(results)
    if log:
        for r in results:
            c = r.predicted.get('correct_rate', math.nan)
            log(f'answer pair {r.pair.name:<22} held-out {_pct(r.heldout_accuracy)}, wrong '
                f'decisions {_pct(r.wrong_rate)}, decision {r.decision_time_s:.1f} s, '
                f'predicted correct {_pct(c)}{" <- chosen" if r is best else ""}'
                f'{f" ({r.reason})" if r.reason else ""}')
    return best, results


def _pct(x: float) -> str:
    return '-' if x is None or not math.isfinite(x) else f'{100 * x:.0f} %'
