"""The calibration gate: is this person ready to drive the arm with this model?

After calibration the person's answer pair is chosen and its closed-loop figures predicted from
held-out calibration data (:mod:`mindgrasp_classifier.answer_pair`). The gate turns them into one
verdict:

``ready``
    The predicted correct rate is at least :data:`READY_CORRECT` and the predicted wrong-grasp
    rate at most :data:`READY_WRONG`.
``needs_training``
    Not ready, but some pair decodes above chance on held-out data (balanced accuracy at least
    :data:`DECODES`): more calibration trials of that pair's classes may get there (the reason
    names them).
``not_ready``
    No pair decodes above :data:`DECODES` on held-out data: this person cannot yet answer with
    any imagery the decoder knows.

The limits were chosen on EEGMMIDB S001-S004 only (src/mindgrasp_classifier/README.md).

    >>> gate_verdict(0.8, 0.01, 0.9, 'hands_feet', ['both_hands'], ['both_feet'])[0]
    'ready'
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from mindgrasp_classifier.answer_pair import (
    TARGET_WRONG_RATE,
    FoldStream,
    PairResult,
    choose_pair,
    heldout_streams,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_common.answer_pair import DEFAULT_PAIR, answer_pair

__all__ = ['DECODES', 'READY_CORRECT', 'READY_WRONG', 'VERDICTS', 'calibrate_answer',
           'gate_verdict', 'unassessed_entries']

VERDICTS = ('ready', 'needs_training', 'not_ready')
#: predicted correct rate (per trial) from which a person is ready
READY_CORRECT = 0.6
#: largest predicted wrong-grasp rate (per trial) of a ready person
READY_WRONG = 0.03
#: held-out balanced accuracy (yes vs no windows) above which a pair decodes at all
DECODES = 0.6


def gate_verdict(correct: float, wrong: float, accuracy: float, pair: str,
                 yes: Sequence[str], no: Sequence[str]) -> tuple[str, str]:
    """(verdict, reason) from the chosen pair's predicted rates and the best held-out accuracy.
    """
    def pct(x: float) -> str:
        return f'{100 * x:.0f} %' if math.isfinite(x) else 'n/a'

    if math.isfinite(correct) and math.isfinite(wrong) and correct >= READY_CORRECT and \
            wrong <= READY_WRONG:
        return 'ready', (f'answer {pair}: predicted {pct(correct)} correct, {pct(wrong)} wrong '
                         'grasps')
    if not (math.isfinite(accuracy) and accuracy >= DECODES):
        return 'not_ready', (f'no answer pair decodes on held-out data (best {pct(accuracy)} '
                             f'balanced, {pct(DECODES)} needed); practise the imagery (e.g. '
                             'with feedback) and calibrate again')
    return 'needs_training', (f'answer {pair} predicted {pct(correct)} correct, {pct(wrong)} '
                              f'wrong grasps: record more trials of {" / ".join(yes)} (yes) and '
                              f'{" / ".join(no)} (no) and calibrate again')


def calibrate_answer(recordings: Sequence[Any], cfg: Any, *,
                     play_classes: set[int] | None = None,
                     target_wrong_rate: float = TARGET_WRONG_RATE,
                     streams: Sequence[FoldStream] | None = None, seed: int = 0,
                     temperature: float | None = None,
                     log: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Choose the answer pair, its thresholds and the gate verdict for one person.

    Parameters
    ----------
    recordings : sequence of Recording
        Labelled calibration recordings (rest events included), one per run.
    cfg : TrainingConfig
        The person's model settings.
    play_classes : set of int, optional
        Classes the person's play data can express (replay subjects); None: all.
    target_wrong_rate : float
        Rate of wrong offer decisions the thresholds aim at.
    streams : sequence of FoldStream, optional
        Held-out streams already computed (:func:`heldout_streams`).
    temperature : float, optional
        The person's model's probability calibration, used by the fold models
        (:func:`heldout_streams`).

    Returns
    -------
    dict
        ``answer_pair`` ({name, yes, no}), ``decision_thresholds`` ({confirm, pass, affirm,
        cancel}, nat s) and ``gate`` (verdict, reason, predicted, target_wrong_rate, pairs):
        the model file's entries.
    """
    if streams is None:
        try:
            streams = heldout_streams(recordings, cfg, temperature=temperature, log=log)
        except ClassifierError as exc:
            # too little calibration to hold any of it out: the model is usable, its person
            # unassessed; the default pair and thresholds, and a verdict that says what to record
            return unassessed_entries(f'the calibration is too small to predict the closed loop '
                                      f'({exc}); record more runs and calibrate again',
                                      target_wrong_rate)
    best, results = choose_pair(streams, play_classes=play_classes,
                                target_wrong_rate=target_wrong_rate, seed=seed, log=log)
    return answer_entries(best, results, target_wrong_rate, play_classes)


def answer_entries(best: PairResult, results: Sequence[PairResult], target_wrong_rate: float,
                   play_classes: set[int] | None = None) -> dict[str, Any]:
    """The model entries of a choice (:func:`calibrate_answer`)."""
    accs = [r.heldout_accuracy for r in results if math.isfinite(r.heldout_accuracy)]
    best_acc = max(accs) if accs else math.nan
    pred = best.predicted
    d = best.pair.to_dict()
    verdict, reason = gate_verdict(pred.get('correct_rate', math.nan),
                                   pred.get('wrong_rate', math.nan), best_acc, best.pair.name,
                                   d['yes'][:1], d['no'][:1])
    if play_classes is not None:
        from mindgrasp_common.mi import DECODER_CLASS_NAMES

        reason += (f' (pairs restricted to the classes the play data hold: '
                   f'{", ".join(DECODER_CLASS_NAMES[c] for c in sorted(play_classes))}, rest)')

    def num(x: float) -> float | None:
        return round(float(x), 4) if x is not None and math.isfinite(x) else None

    thresholds = best.thresholds or {k: float(v) for k, v in _defaults().items()}
    return {
        'answer_pair': d,
        'decision_thresholds': thresholds,
        'gate': {'verdict': verdict, 'reason': reason,
                 'predicted': {'correct_rate': num(pred.get('correct_rate', math.nan)),
                               'wrong_rate': num(pred.get('wrong_rate', math.nan)),
                               'decision_time_s': num(best.decision_time_s),
                               'trial_time_s': num(pred.get('trial_time_s', math.nan))},
                 'target_wrong_rate': float(target_wrong_rate),
                 'pairs': [r.summary() for r in results]},
    }


def _defaults() -> dict[str, float]:
    from mindgrasp_classifier.answer_pair import DEFAULT_THRESHOLDS

    return DEFAULT_THRESHOLDS


def unassessed_entries(reason: str, target_wrong_rate: float = TARGET_WRONG_RATE
                       ) -> dict[str, Any]:
    """Entries of a model whose calibration could not be held out (``needs_training``, with
    ``reason``): the default pair and thresholds, no prediction."""
    return {'answer_pair': answer_pair(DEFAULT_PAIR).to_dict(),
            'decision_thresholds': {k: float(v) for k, v in _defaults().items()},
            'gate': {'verdict': 'needs_training', 'reason': reason,
                     'predicted': {'correct_rate': None, 'wrong_rate': None,
                                   'decision_time_s': None, 'trial_time_s': None},
                     'target_wrong_rate': float(target_wrong_rate), 'pairs': []}}


def default_entries() -> dict[str, Any]:
    """Entries of a model whose person was not assessed: the default pair, no verdict."""
    return {'answer_pair': answer_pair(DEFAULT_PAIR).to_dict()}
