"""The answer pair and the calibration gate on real EEG (EEGMMIDB): held-out streams through the
real decoder and the controller's Evidence choose each person's pair, and the gate's verdicts."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mindgrasp_classifier.answer_pair import candidate_pairs, heldout_streams
from mindgrasp_classifier.gate import calibrate_answer, gate_verdict
from mindgrasp_classifier.training import TrainingConfig
from mindgrasp_common.mi import REST

pytestmark = pytest.mark.slow

#: the replay subject's decoder settings (mindgrasp_experiments.subjects.REPLAY_TRAINING)
CFG = TrainingConfig(pipeline='ts_lr', classes=[0, 1, 2, 3, 4], window=2.0, tmin=0.5, tmax=4.0)


def recordings(subject: int, runs: tuple[int, ...]) -> list:
    from mindgrasp_eeg.subject_file import EEGMMIDB_EVENTS, ReplayFile, _eegbci_paths
    from mindgrasp_experiments.subjects import labelled_recordings

    files = [ReplayFile(_eegbci_paths(f'eegbci:{subject}:{r}')[0], EEGMMIDB_EVENTS[r],
                        f'eegbci:{subject}:{r}') for r in runs]
    from mindgrasp_eeg.player import load_recording

    return labelled_recordings(files, [load_recording(f.path) for f in files])


@pytest.fixture(scope='module')
def s001(eegbci_path: str) -> list:
    """S001's held-out streams (runs 4 and 6, each held out by halves)."""
    return heldout_streams(recordings(1, (4, 6)), CFG, temperature=1.0)


def test_pairs_follow_the_decoders_and_the_play_datas_classes() -> None:
    names = [p.name for p in candidate_pairs([0, 1, 2, 3, REST], rest_pairs=True)]
    assert names[:3] == ['hands_feet', 'left_right', 'mi_rest'] and 'both_hands_rest' in names
    # S006-S012 play only run 12 (left / right hand): hands and feet cannot answer
    names = [p.name for p in candidate_pairs([0, 1, 2, 3, REST], play_classes={0, 1},
                                             rest_pairs=True)]
    assert names[:2] == ['left_right', 'mi_rest'] and not any('both' in n for n in names)
    mi_rest = candidate_pairs([0, 1, 2, 3, REST], play_classes={0, 1}, rest_pairs=True)[1]
    assert mi_rest.yes[:2] == (0, 1) and mi_rest.no == (REST,)


def test_pairs_with_rest_are_not_chosen_automatically() -> None:
    """Imagery against rest predicted far better than it played (wrong grasps), so the
    automatic choice only weighs pairs of two imagery classes."""
    names = [p.name for p in candidate_pairs([0, 1, 2, 3, REST])]
    assert names[:2] == ['hands_feet', 'left_right'] and len(names) == 10
    assert not any('rest' in n for n in names)
    names = [p.name for p in candidate_pairs([0, 1, 2, 3, REST], play_classes={0, 1})]
    assert names == ['left_right']


def test_s001_is_ready_with_hands_and_feet(s001: list) -> None:
    entries = calibrate_answer([], CFG, streams=s001)
    assert entries['answer_pair']['name'] == 'hands_feet'
    gate = entries['gate']
    assert gate['verdict'] == 'ready', gate
    assert gate['predicted']['correct_rate'] >= 0.6 and gate['predicted']['wrong_rate'] <= 0.03
    assert set(entries['decision_thresholds']) == {'confirm', 'pass', 'affirm', 'cancel'}
    accuracy = {p['name']: p['heldout_accuracy'] for p in gate['pairs']}
    assert accuracy['hands_feet'] > 0.9 > accuracy['left_right'] > 0.6


def test_s001_without_hands_and_feet_in_its_play_data_answers_otherwise(s001: list) -> None:
    entries = calibrate_answer([], CFG, streams=s001, play_classes={0, 1})
    assert entries['answer_pair']['name'] not in ('hands_feet',)
    assert not {'both_hands', 'both_feet'} & {*entries['answer_pair']['yes'][:1],
                                               *entries['answer_pair']['no'][:1]}
    assert 'restricted to the classes the play data hold: left_hand, right_hand' in \
        entries['gate']['reason']


def test_shuffled_labels_are_not_ready(eegbci_path: str) -> None:
    rng = np.random.default_rng(0)
    shuffled = []
    for rec in recordings(1, (4, 6)):
        events = rec.events.copy()
        events[:, 1] = rng.permutation(events[:, 1])
        shuffled.append(dataclasses.replace(rec, events=events))
    entries = calibrate_answer(shuffled, CFG, temperature=1.0)
    assert entries['gate']['verdict'] == 'not_ready', entries['gate']
    assert 'no answer pair decodes on held-out data' in entries['gate']['reason']


def test_the_verdicts_and_what_to_train() -> None:
    assert gate_verdict(0.9, 0.0, 0.95, 'hands_feet', ['both_hands'], ['both_feet'])[0] == 'ready'
    verdict, reason = gate_verdict(0.3, 0.0, 0.7, 'left_right', ['left_hand'], ['right_hand'])
    assert verdict == 'needs_training'
    assert 'record more trials of left_hand (yes) and right_hand (no)' in reason
    assert gate_verdict(0.9, 0.1, 0.9, 'hands_feet', ['both_hands'], ['both_feet'])[0] == \
        'needs_training'                              # too many wrong grasps predicted
    assert gate_verdict(0.0, 0.0, 0.52, 'mi_rest', ['left_hand'], ['rest'])[0] == 'not_ready'


def test_the_choice_keeps_the_default_only_when_something_predicts_a_grasp() -> None:
    from mindgrasp_classifier.answer_pair import PairResult, select
    from mindgrasp_common.answer_pair import answer_pair

    def result(name: str, correct: float, accuracy: float) -> PairResult:
        return PairResult(answer_pair(name), heldout_accuracy=accuracy, decision_time_s=5.0,
                          predicted={'correct_rate': correct})

    # S003 (measured): every pair predicts no correct grasp; left / right separates best
    assert select([result('hands_feet', 0.0, 0.46), result('left_right', 0.0, 0.61),
                   result('mi_rest', 0.0, 0.51)]).pair.name == 'left_right'
    assert select([result('hands_feet', 0.98, 0.81),
                   result('left_right', 1.0, 0.86)]).pair.name == 'hands_feet'
    assert select([result('hands_feet', 0.86, 0.81),
                   result('left_right', 1.0, 0.86)]).pair.name == 'left_right'     # S002
