"""The person's answer pair in the controller: evidence over sets of classes, the pair and
thresholds taken from the classifier model (or overridden), the hardware readiness check, and
the subjects answering with the pair in force."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from mindgrasp_common.mi import REST
from mindgrasp_eeg.subject import VirtualSubject, scan_class
from mindgrasp_fsm.answer import readiness_problem
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.evidence import Evidence, log_ratio
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import MiClass, State

from .test_scan_paradigm import CLASSES, UNIFORM, pred, probs, run_until

LEFT = probs(left=0.6, right=0.1)
RIGHT = probs(left=0.1, right=0.6)


def model_file(folder: Path, pair: dict, thresholds: dict | None = None,
               gate: dict | None = None) -> Path:
    """A model JSON with the answer entries only (the controller reads nothing else)."""
    doc = {'answer_pair': pair, 'gate': gate or {'verdict': 'ready', 'reason': 'test'}}
    if thresholds:
        doc['decision_thresholds'] = thresholds
    path = folder / 'person.json'
    path.write_text(json.dumps(doc))
    return path


def test_evidence_for_a_set_sums_its_probabilities():
    p = probs(left=0.2, right=0.2, hands=0.1, feet=0.1)                # rest 0.4
    assert log_ratio(p, CLASSES, [0, 1, 2, 3], [REST]) == pytest.approx(math.log(0.6 / 0.4))
    assert log_ratio(p, CLASSES, 2, [3]) == log_ratio(p, CLASSES, [2], [3])
    ev = Evidence([0, 1, 2, 3], [REST], threshold=1.0)
    ev.reset(0.0)
    for k in range(1, 17):
        ev.update(pred(k / 16, p))
    assert ev.value == pytest.approx(math.log(1.5))


def test_the_models_pair_and_thresholds_are_used_unless_overridden(tmp_path: Path):
    model = model_file(tmp_path, {'name': 'left_right', 'yes': ['left_hand'],
                                  'no': ['right_hand']},
                       {'confirm': 1.0, 'pass': 1.0, 'affirm': 1.0, 'cancel': 2.0})
    fsm = GraspFsm(FsmParams(paradigm='scan', classifier_model=str(model)))
    assert fsm.answer.name == 'left_right'
    assert fsm.decision_thresholds() == {'confirm': 1.0, 'pass': 1.0, 'affirm': 1.0,
                                         'cancel': 2.0}
    explicit = GraspFsm(FsmParams(paradigm='scan', classifier_model=str(model),
                                  model_thresholds=False, confirm_threshold=4.0))
    assert explicit.decision_thresholds()['confirm'] == 4.0
    other = GraspFsm(FsmParams(paradigm='scan', classifier_model=str(model),
                               answer_pair='hands_feet'))
    assert other.answer.name == 'hands_feet'
    assert other.decision_thresholds()['confirm'] == 3.0      # the model's are for its own pair
    assert GraspFsm(FsmParams(paradigm='scan')).answer.name == 'hands_feet'


def test_the_controller_confirms_and_declines_with_left_right(tmp_path: Path):
    model = model_file(tmp_path, {'name': 'left_right', 'yes': ['left_hand'],
                                  'no': ['right_hand']})
    kw = dict(paradigm='scan', lock_duration=0.5, offer_timeout=6.0, offer_delay=0.5,
              classifier_model=str(model))
    fsm = GraspFsm(FsmParams(**kw))
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    hands = probs(hands=0.6, feet=0.1)           # both hands says nothing in this pair
    out, t = run_until(fsm, t, 3.0, hands, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert out.state == State.CENTER_OBJECT and out.offered
    out, t = run_until(fsm, t, 3.0, LEFT, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert out.state == State.INITIAL_APPROACH
    assert 'confirmed the red cube (left-hand evidence' in out.reason
    fsm = GraspFsm(FsmParams(**kw))
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    out, t = run_until(fsm, t, 3.0, RIGHT, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert 'declined (right-hand evidence' in out.reason


def test_a_bad_pair_name_is_one_line():
    with pytest.raises(FsmError, match="The parameter 'answer_pair': Unknown answer pair "
                                       "'hands_nose'"):
        FsmParams(answer_pair='hands_nose').validate()


def test_the_hardware_check_refuses_a_model_that_is_not_ready(tmp_path: Path):
    pair = {'name': 'hands_feet', 'yes': ['both_hands'], 'no': ['both_feet']}
    ready = model_file(tmp_path, pair)
    assert readiness_problem(FsmParams(classifier_model=str(ready),
                                       require_ready_model=True)) is None
    unready = model_file(tmp_path, pair, gate={'verdict': 'needs_training',
                                               'reason': 'too slow'})
    problem = readiness_problem(FsmParams(classifier_model=str(unready),
                                          require_ready_model=True))
    assert problem is not None and 'is not ready (needs_training: too slow)' in problem
    assert 'override with require_ready_model:=false' in problem
    assert readiness_problem(FsmParams(classifier_model=str(unready))) is None
    assert 'no calibration gate verdict' in readiness_problem(FsmParams(
        classifier_model='package://mindgrasp_classifier/models/default_classifier.json',
        require_ready_model=True))


def test_the_subject_answers_with_the_pair_in_force():
    from mindgrasp_common.types import SceneObject

    target = SceneObject(0, 'red', 'cube', [0.5 * math.cos(0.7), 0.5 * math.sin(0.7), 0.025])
    assert scan_class(target, 0.7, State.CENTER_OBJECT, offered=True, yes=0, no=1) == 0
    assert scan_class(target, 0.0, State.CENTER_OBJECT, offered=True, yes=0, no=1) == 1
    assert scan_class(target, 0.0, State.INITIAL_APPROACH, yes=2, no=None) is None   # mi_rest
    subject = VirtualSubject('pursue')
    subject.set_fsm(2, paradigm='scan', offered=True, yes_classes=[1], no_classes=[4])
    assert (subject.yes_class, subject.no_class) == (MiClass.RIGHT_HAND, None)
    subject.set_fsm(2, paradigm='scan', offered=True)          # a controller that does not say
    assert (subject.yes_class, subject.no_class) == (MiClass.RIGHT_HAND, None)
