"""The scan paradigm and its evidence: the arm offers, the person answers yes/no, cancels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_common.mi import REST
from mindgrasp_eeg.subject import scan_class
from mindgrasp_fsm.evidence import Evidence, log_ratio
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import FsmInputs, JointStateIn, MiClass, Prediction, State

from .conftest import CAMERA, HOME, frame, observation

CLASSES = (0, 1, 2, 3, REST)
CENTRED = observation(64, 64, 0.01, 0.8)


def probs(**p: float) -> np.ndarray:
    """Probabilities over CLASSES; unnamed classes share what is left."""
    names = ('left', 'right', 'hands', 'feet', 'rest')
    given = {names.index(k): v for k, v in p.items()}
    rest = (1.0 - sum(given.values())) / (len(names) - len(given))
    return np.array([given.get(i, rest) for i in range(len(names))])


def pred(t: float, p: np.ndarray) -> Prediction:
    return Prediction(int(np.argmax(p)) if np.argmax(p) < 4 else REST, 0.5, t,
                      probabilities=p, classes=CLASSES)


HANDS = probs(hands=0.6, feet=0.1)           # log ratio hands/feet = log 6
FEET = probs(hands=0.1, feet=0.6)
UNIFORM = probs()


# ------------------------------------------------------------------------------ evidence
def test_log_ratio_against_named_classes_and_fallback():
    assert log_ratio(HANDS, CLASSES, 2, [3]) == pytest.approx(math.log(6))
    # against a class the decoder does not know: every other class
    assert log_ratio(np.array([0.5, 0.25, 0.25]), (0, 2, 3), 2, [REST]) == pytest.approx(
        math.log(0.25 / 0.75))
    assert log_ratio(HANDS, CLASSES, 2, [3]) is not None
    assert log_ratio(HANDS[:4], CLASSES, 2, [3]) is None          # shapes do not match


def test_evidence_is_a_time_integral_whatever_the_prediction_rate():
    values = []
    for rate in (8.0, 16.0):
        ev = Evidence(2, [3], threshold=100.0, clip=5.0)
        ev.reset(since=0.0)
        for k in range(1, int(2 * rate) + 1):
            ev.update(pred(k / rate, HANDS))
        values.append(ev.value)
    assert values[0] == pytest.approx(2 * math.log(6))
    assert values[1] == pytest.approx(values[0])


def test_evidence_clips_counts_only_new_predictions_and_ignores_missing_probabilities():
    ev = Evidence(2, [3], threshold=10.0, clip=1.0)
    ev.reset(since=0.0)
    strong = probs(hands=0.98, feet=0.001)
    ev.update(pred(0.25, strong))
    assert ev.value == pytest.approx(0.25)                   # clipped to 1 nat x 0.25 s
    ev.update(pred(0.25, strong))                            # the same stamp again: ignored
    ev.update(Prediction(2, 1.0, 0.5))                       # no probabilities: nothing added
    assert ev.value == pytest.approx(0.25)
    ev.update(pred(-1.0, strong))                            # older than the reset: ignored
    assert ev.value == pytest.approx(0.25)


def test_cusum_floor_and_sprt_reject():
    cusum = Evidence(2, [3], threshold=2.0)
    sprt = Evidence(2, [3], threshold=2.0, reject_threshold=1.0)
    for ev in (cusum, sprt):
        ev.reset(since=0.0)
        for k in range(1, 17):
            ev.update(pred(k / 16, FEET))
    assert cusum.value == 0.0 and not cusum.rejected and not cusum.reached
    assert sprt.rejected and sprt.value == pytest.approx(-1.0)


# ------------------------------------------------------------------------------ controller
def scan_fsm(**kw: object) -> GraspFsm:
    return GraspFsm(FsmParams(paradigm='scan', lock_duration=0.5, offer_timeout=6.0,
                              offer_delay=0.5, confirm_threshold=3.0, pass_threshold=3.0,
                              cancel_threshold=3.0, **kw))


def tick(fsm: GraspFsm, t: float, p: np.ndarray, obs=CENTRED, q=None) -> object:
    q = HOME.copy() if q is None else q
    return fsm.tick(FsmInputs(time=t, joints=JointStateIn(q, np.zeros(6), t),
                              prediction=pred(t, p), vision=frame(t, obs), camera=CAMERA))


def run_until(fsm: GraspFsm, t: float, seconds: float, p: np.ndarray, stop=None, obs=CENTRED):
    end = t + seconds
    out = None
    while t < end:
        out = tick(fsm, t, p, obs)
        t += 0.02
        if stop is not None and stop(out):
            break
    return out, t


def test_scan_searches_by_itself_without_steering():
    fsm = scan_fsm()
    out, _ = run_until(fsm, 0.0, 1.0, UNIFORM, obs=None)
    assert out.state == State.OBJECT_SEARCH and out.paradigm == 'scan'
    assert out.joint_velocities[0] != 0.0                    # the sweep turns joint 1


def test_scan_offers_then_commits_on_both_hands():
    fsm = scan_fsm()
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    assert out.offered and out.state == State.CENTER_OBJECT
    # rest (uniform probabilities) never commits: the offer runs out and the arm passes on
    out, t = run_until(fsm, t, 3.0, UNIFORM)
    assert out.state == State.CENTER_OBJECT and out.offered
    out, t = run_until(fsm, t, 3.0, HANDS, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert out.state == State.INITIAL_APPROACH
    assert 'confirmed the red cube' in out.reason


def test_scan_passes_on_both_feet_and_on_timeout():
    fsm = scan_fsm()
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    out, t = run_until(fsm, t, 3.0, FEET, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert out.state == State.OBJECT_SEARCH and 'declined' in out.reason
    fsm = scan_fsm()
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    out, t = run_until(fsm, t, 7.0, UNIFORM, stop=lambda o: o.state != State.CENTER_OBJECT)
    assert out.state == State.OBJECT_SEARCH and 'not confirmed in 6.0 s' in out.reason


def test_scan_cancel_backs_out_before_the_gripper_closes():
    fsm = scan_fsm()
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    out, t = run_until(fsm, t, 3.0, HANDS, stop=lambda o: o.state == State.INITIAL_APPROACH)
    out, t = run_until(fsm, t, 1.0, HANDS)                    # going on: no cancel
    assert out.state == State.INITIAL_APPROACH and out.cancel_evidence == 0.0
    out, t = run_until(fsm, t, 4.0, FEET, stop=lambda o: o.locked)
    assert out.locked and 'cancelled the approach to the red cube' in out.reason
    assert fsm.outcome == 'cancelled'
    out, t = run_until(fsm, t, 0.6, FEET)
    assert out.state == State.RETURN_TO_START


def test_paper_paradigm_takes_rest_as_no_command():
    fsm = GraspFsm(FsmParams(paradigm='paper', lock_duration=0.5))
    rest = probs(rest=0.9)
    out, _ = run_until(fsm, 0.0, 3.0, rest)
    assert out.state == State.OBJECT_SEARCH
    assert np.all(out.joint_velocities == 0.0)


# ------------------------------------------------------------------------------ the subject
def test_scan_subject_answers_by_where_the_arm_points():
    from mindgrasp_common.types import SceneObject

    target = SceneObject(0, 'red', 'cube', [0.5 * math.cos(0.7), 0.5 * math.sin(0.7), 0.025])
    assert scan_class(target, 0.7, State.CENTER_OBJECT, offered=True) == MiClass.BOTH_HANDS
    assert scan_class(target, 0.0, State.CENTER_OBJECT, offered=True) == MiClass.BOTH_FEET
    assert scan_class(target, 0.0, State.OBJECT_SEARCH) is None
    assert scan_class(target, 0.0, State.INITIAL_APPROACH) == MiClass.BOTH_FEET
    assert scan_class(target, 0.7, State.FINAL_APPROACH) == MiClass.BOTH_HANDS
    assert scan_class(target, 0.0, State.OBJECT_SEARCH, stopped=True) == MiClass.BOTH_HANDS
    assert scan_class(None, 0.0, State.CENTER_OBJECT, offered=True) is None


def test_scan_final_approach_waits_for_go_on():
    big = observation(64, 64, 0.2, 0.5)
    for answer, end_state, words in ((HANDS, State.FINAL_APPROACH, 'fills'),
                                     (UNIFORM, State.RETURN_TO_START, 'no go-on within 6.0 s')):
        fsm = scan_fsm()
        out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
        out, t = run_until(fsm, t, 3.0, HANDS, stop=lambda o: o.state == State.INITIAL_APPROACH)
        # the object is close at once: without a go-on the arm holds there
        out, t = run_until(fsm, t, 0.3, UNIFORM, obs=big)
        assert out.state == State.INITIAL_APPROACH and out.phase == 'waiting for go-on'
        out, t = run_until(fsm, t, 8.0, answer, obs=big, stop=lambda o: o.locked)
        assert out.locked and words in out.reason
        out, t = run_until(fsm, t, 0.6, answer, obs=big)
        assert out.state == end_state


def test_scan_does_not_offer_a_passed_object_again_until_both_ends_were_reached():
    fsm = scan_fsm()
    out, t = run_until(fsm, 0.0, 3.0, UNIFORM, stop=lambda o: o.offered)
    out, t = run_until(fsm, t, 3.0, FEET, stop=lambda o: o.state == State.OBJECT_SEARCH)
    assert 'declined' in out.reason
    # the same object still in view (the arm has not turned in this test): not offered again
    out, t = run_until(fsm, t, 2.0, UNIFORM)
    assert out.state == State.OBJECT_SEARCH and 'turning on past the red cube' in out.phase
    assert out.joint_velocities[0] != 0.0
    # the scan reaches one end, then the other: the object is offered again
    p = fsm.params
    lo, hi = p.joint_lower_limits[0], p.joint_upper_limits[0]
    for end in (hi, lo):
        q = HOME.copy()
        q[0] = end
        tick(fsm, t, UNIFORM, obs=None, q=q)
        t += 0.02
    out, t = run_until(fsm, t, 3.0, UNIFORM, stop=lambda o: o.state == State.CENTER_OBJECT)
    assert out.state == State.CENTER_OBJECT
