"""GraspFsm on synthetic inputs: every transition of the paper, locks, watchdog, BCI scaling."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.grasp_fsm import GraspFsm, clamp_to_limits
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import (
    FsmInputs,
    GripperCommand,
    GripperState,
    JointStateIn,
    MiClass,
    Prediction,
    State,
    StopKind,
)

from .conftest import HOME, inputs, observation, run

CENTRED = observation(64, 64, 0.01, 0.8)
OFF_RIGHT = observation(64 + 0.3 * 128, 64, 0.01, 0.8)
BIG = observation(64, 64, 0.2, 0.5)
NEAR = observation(64, 64, 0.05, 0.3)
HOLDING = GripperState(opening=0.6, force=float('nan'), stamp=0.0, contact=True)
EMPTY = GripperState(opening=0.0, force=float('nan'), stamp=0.0, contact=False)


def _near_limit_q() -> np.ndarray:
    q = HOME.copy()
    q[1] = FsmParams().joint_upper_limits[1] - 0.05
    return q


def _settle(fsm: GraspFsm, t: float, **kwargs: object) -> tuple[list, float]:
    """Tick until the lock (if any) is over: 0.7 s at the fixture's 0.5 s lock."""
    return run(fsm, t, 0.7, **kwargs)


# (name, start state, Center-Object continuation, autonomous, inputs, seconds, end state, locked)
TRANSITIONS = [
    ('1->2 both hands selects the object', State.OBJECT_SEARCH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': CENTRED}, 1.54, State.CENTER_OBJECT, False),
    ('1->2 autonomous search sees an object', State.OBJECT_SEARCH, None, True,
     {'cls': None, 'obs': CENTRED}, 0.4, State.CENTER_OBJECT, False),
    ('2->3 centred after selection', State.CENTER_OBJECT, State.INITIAL_APPROACH, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': CENTRED}, 0.4, State.INITIAL_APPROACH, False),
    ('2->4 centred again during the final approach', State.CENTER_OBJECT, State.FINAL_APPROACH,
     False, {'cls': MiClass.BOTH_HANDS, 'obs': CENTRED}, 0.4, State.FINAL_APPROACH, False),
    ('2->1 object lost while centring', State.CENTER_OBJECT, State.INITIAL_APPROACH, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': None}, 1.6, State.OBJECT_SEARCH, False),
    ('3->2 object drifts off centre', State.INITIAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': OFF_RIGHT}, 0.04, State.CENTER_OBJECT, False),
    ('3->4 object fills the image', State.INITIAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': BIG}, 0.04, State.INITIAL_APPROACH, True),
    ('3->4 object near in depth', State.INITIAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': NEAR}, 0.04, State.INITIAL_APPROACH, True),
    ('3->4 approach joint near its limit', State.INITIAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': CENTRED, 'q': _near_limit_q()}, 0.04,
     State.INITIAL_APPROACH, True),
    ('3->1 object lost during the approach', State.INITIAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': None}, 1.6, State.INITIAL_APPROACH, True),
    ('4->2 off centre before the autonomous approach', State.FINAL_APPROACH, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': OFF_RIGHT}, 0.04, State.CENTER_OBJECT, False),
    ('6->1 back at the start position', State.RETURN_TO_START, None, False,
     {'cls': MiClass.BOTH_HANDS, 'obs': None}, 0.04, State.RETURN_TO_START, True),
]
AFTER_LOCK = {
    '3->4 object fills the image': State.FINAL_APPROACH,
    '3->4 object near in depth': State.FINAL_APPROACH,
    '3->4 approach joint near its limit': State.FINAL_APPROACH,
    '3->1 object lost during the approach': State.OBJECT_SEARCH,
    '6->1 back at the start position': State.OBJECT_SEARCH,
}


@pytest.mark.parametrize(('name', 'start', 'center_next', 'autonomous', 'kw', 'seconds', 'end',
                          'locked'), TRANSITIONS, ids=[t[0] for t in TRANSITIONS])
def test_transition(params: FsmParams, name: str, start: State, center_next: State | None,
                    autonomous: bool, kw: dict, seconds: float, end: State, locked: bool) -> None:
    params.autonomous = autonomous
    fsm = GraspFsm.from_params(params)
    fsm.force_state(start, center_next=center_next)
    outs, t = run(fsm, 0.0, seconds, **kw)
    assert outs[-1].state == end, outs[-1].reason
    assert outs[-1].locked == locked
    if locked:
        # the lock: every joint stopped, state unchanged, then the new state
        assert all(np.all(o.joint_velocities == 0) for o in outs if o.locked)
        outs, _ = _settle(fsm, t, **kw)
        assert outs[-1].state == AFTER_LOCK[name]
        assert outs[-1].previous_state == start
        assert not outs[-1].locked


def test_a_single_both_hands_window_does_not_select(fsm: GraspFsm) -> None:
    """One misdecoded window while the user turns must not start a grasp (bci_select_dwell)."""
    outs, t = run(fsm, 0.0, 0.3, cls=MiClass.BOTH_HANDS, obs=CENTRED)
    outs2, _ = run(fsm, t, 0.04, cls=MiClass.LEFT_HAND, obs=CENTRED)
    outs3, _ = run(fsm, t + 0.04, 0.3, cls=MiClass.BOTH_HANDS, obs=CENTRED)
    assert all(o.state == State.OBJECT_SEARCH for o in outs + outs2 + outs3)


def test_both_hands_without_object_stays_in_search(fsm: GraspFsm) -> None:
    outs, _ = run(fsm, 0.0, 0.5, cls=MiClass.BOTH_HANDS, obs=None)
    assert outs[-1].state == State.OBJECT_SEARCH
    assert np.all(outs[-1].joint_velocities == 0)


@pytest.mark.parametrize(('cls', 'sign'), [(MiClass.LEFT_HAND, 1.0), (MiClass.RIGHT_HAND, -1.0),
                                           (MiClass.BOTH_FEET, 0.0)])
@pytest.mark.parametrize('cert', [0.4, 1.0])
def test_search_turns_joint1_scaled_by_certainty(fsm: GraspFsm, cls: int, sign: float,
                                                 cert: float) -> None:
    out = fsm.tick(inputs(0.0, cls=cls, cert=cert, obs=None))
    expected = np.zeros(6)
    expected[0] = sign * fsm.params.search_gain * cert
    np.testing.assert_allclose(out.joint_velocities, expected)


def test_initial_approach_classes(fsm: GraspFsm) -> None:
    p = fsm.params
    fsm.force_state(State.INITIAL_APPROACH)
    out = fsm.tick(inputs(0.0, cls=MiClass.BOTH_HANDS, cert=1.0, obs=CENTRED))
    assert out.joint_velocities[1] == pytest.approx(p.approach_gain * 1.0)
    out = fsm.tick(inputs(0.02, cls=MiClass.BOTH_HANDS, cert=1.5, obs=CENTRED))
    assert out.joint_velocities[1] == pytest.approx(p.approach_gain * 1.5)
    out = fsm.tick(inputs(0.04, cls=MiClass.BOTH_FEET, cert=1.0, obs=CENTRED))
    assert out.joint_velocities[1] == pytest.approx(-p.retreat_gain)
    out = fsm.tick(inputs(0.06, cls=MiClass.LEFT_HAND, cert=1.0, obs=CENTRED))
    assert out.joint_velocities[1] == 0 and out.joint_velocities[0] == pytest.approx(p.turn_gain)
    out = fsm.tick(inputs(0.08, cls=MiClass.RIGHT_HAND, cert=1.0, obs=CENTRED))
    assert out.joint_velocities[0] == pytest.approx(-p.turn_gain)
    # no class above the certainty threshold: the slow default approach
    out = fsm.tick(inputs(0.10, cls=MiClass.BOTH_FEET, cert=0.2, obs=CENTRED))
    assert out.joint_velocities[1] == pytest.approx(p.default_approach_velocity)
    assert out.state == State.INITIAL_APPROACH


def test_centring_is_proportional_on_joints_1_and_5(fsm: GraspFsm) -> None:
    p = fsm.params
    fsm.force_state(State.CENTER_OBJECT, center_next=State.INITIAL_APPROACH)
    obs = observation(64 + 12.8, 64 - 6.4)
    out = fsm.tick(inputs(0.0, obs=obs))
    assert out.joint_velocities[0] == pytest.approx(p.center_sign_joint1 * p.center_gain_joint1
                                                    * 0.1)
    assert out.joint_velocities[4] == pytest.approx(p.center_sign_joint5 * p.center_gain_joint5
                                                    * -0.05)
    assert np.all(out.joint_velocities[[1, 2, 3, 5]] == 0)


def test_bci_ignored_in_autonomous_states(params: FsmParams) -> None:
    q = HOME + np.array([0.3, 0.0, 0.0, 0.0, 0.0, 0.0])
    outs = []
    for cls in (MiClass.LEFT_HAND, MiClass.RIGHT_HAND, MiClass.BOTH_FEET):
        fsm = GraspFsm.from_params(params)
        fsm.force_state(State.RETURN_TO_START)
        outs.append(run(fsm, 0.0, 0.5, q=q, cls=cls)[0][-1])
    for out in outs[1:]:
        np.testing.assert_allclose(out.joint_velocities, outs[0].joint_velocities)
    assert outs[0].joint_velocities[0] < 0   # back towards home


def test_center_timeout_goes_on(params: FsmParams) -> None:
    params.center_timeout = 0.5
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.CENTER_OBJECT, center_next=State.INITIAL_APPROACH)
    obs = observation(64 + 0.1 * 128, 64)
    outs, _ = run(fsm, 0.0, 0.6, obs=obs)
    assert outs[-1].state == State.INITIAL_APPROACH
    assert 'timed out' in outs[-1].reason


def test_return_timeout(params: FsmParams) -> None:
    params.return_timeout = 0.3
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.RETURN_TO_START)
    q = HOME + 0.5
    outs, t = run(fsm, 0.0, 0.4, q=q)
    assert outs[-1].locked and 'timed out' in outs[-1].reason
    outs, _ = _settle(fsm, t, q=q)
    assert outs[-1].state == State.OBJECT_SEARCH


# ------------------------------------------------------------------------- state 5 transitions
def _grasp_fsm(params: FsmParams, attempt: int = 0) -> GraspFsm:
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.FINAL_APPROACH, attempt=attempt)
    fsm.policy.object_position = np.array([0.45, 0.0, 0.025])
    fsm.policy.shape = 'cube'
    fsm.force_state(State.GRASP_OBJECT, attempt=attempt)
    return fsm


def _grasp_pose() -> np.ndarray:
    fsm = GraspFsm.from_params(FsmParams())
    q = fsm.kinematics.grasp_ik(np.array([0.45, 0.0, 0.025]), np.pi, HOME)
    assert q is not None
    return q


def _drive(fsm: GraspFsm, q: np.ndarray, gripper: GripperState, seconds: float,
           t0: float = 0.0) -> tuple[list, np.ndarray, float]:
    """Closed loop on a kinematic arm (q integrates the commanded velocities)."""
    outs = []
    t = t0
    dt = 0.02
    while t < t0 + seconds:
        g = dataclasses.replace(gripper, stamp=t)
        out = fsm.tick(inputs(t, q=q, obs=None, gripper=g))
        q = q + out.joint_velocities * dt
        outs.append(out)
        t += dt
    return outs, q, t


def test_5_to_6_checked_grasp(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    outs, _q, _ = _drive(fsm, _grasp_pose(), HOLDING, 8.0)
    states = [o.state for o in outs]
    assert State.RETURN_TO_START in states
    phases = {o.phase for o in outs}
    assert {'close', 'lift', 'check_lift', 'hold'} <= phases
    assert fsm.outcome == 'holding'
    assert outs[0].gripper.position == params.gripper_closed_position
    # after the fingers stall on the object the hand holds a little past that point (compliant
    # grip), and keeps holding during the return
    hold = (1.0 - HOLDING.opening) + params.grip_squeeze
    after = [o for o in outs if o.phase != 'close']
    assert after and all(o.gripper.position == pytest.approx(hold) for o in after)


def test_5_to_4_retry_when_the_fingers_close_on_nothing(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    outs, _, _ = _drive(fsm, _grasp_pose(), EMPTY, 8.0)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered, [o.reason for o in outs[-3:]]
    assert entered[0].previous_state == State.GRASP_OBJECT
    assert entered[0].grasp_attempts == 1
    assert 'retrying' in entered[0].reason and 'closed on nothing' in entered[0].reason
    # opened before retreating
    assert any(o.phase == 'retreat' and o.gripper.position == 0.0 for o in outs)


def test_5_to_6_fails_after_the_retries(params: FsmParams) -> None:
    fsm = _grasp_fsm(params, attempt=params.grasp_retries)
    outs, _, _ = _drive(fsm, _grasp_pose(), EMPTY, 8.0)
    returning = [o for o in outs if o.state == State.RETURN_TO_START]
    assert returning and 'grasp failed' in returning[0].reason
    assert returning[0].previous_state == State.GRASP_OBJECT
    assert fsm.outcome == 'failed'
    assert all(o.state != State.FINAL_APPROACH for o in outs)


def test_a_late_gripper_state_seen_again_is_no_stall_of_the_fingers(params: FsmParams) -> None:
    """Ticks that see the same gripper state again (the driver's states are late on a loaded
    machine) are no evidence that the fingers stopped: the closing goes on until states show
    the fingers stopped, and then the grasp is judged. Judged per tick, the repeated open state
    read as fingers stalled at 0.3 s and the grasp failed with the hand round the cube."""
    fsm = _grasp_fsm(params)
    q = _grasp_pose()
    late_open = GripperState(opening=1.0, force=0.0, stamp=0.0, contact=False,
                             fingers_in_contact=0)
    outs, t = [], 0.0
    while t < 0.8:
        outs.append(fsm.tick(inputs(t, q=q, obs=None, gripper=late_open)))
        t += 0.02
    assert all(o.state == State.GRASP_OBJECT and o.phase == 'close' for o in outs), \
        [(o.state, o.phase, o.reason) for o in outs if o.phase != 'close'][:1]
    outs, _, _ = _drive(fsm, q, HOLDING, 1.2, t0=t)
    assert any(o.phase == 'lift' for o in outs)


def test_slip_after_lift_retries(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    q = _grasp_pose()
    outs, q, t = _drive(fsm, q, HOLDING, 1.2)
    assert outs[-1].phase == 'lift'
    outs, _, _ = _drive(fsm, q, EMPTY, 6.0, t0=t)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and 'slipped' in entered[0].reason


def test_4_to_6_abort_when_out_of_reach(fsm: GraspFsm) -> None:
    fsm.force_state(State.FINAL_APPROACH)
    # an object seen far beyond the arm's reach (2.5 m along the optical axis)
    far = observation(64, 64, 0.001, 2.5)
    outs, _t = run(fsm, 0.0, 1.5, obs=far, gripper=GripperState(1.0, 0.0, 0.0))
    locked = [o for o in outs if o.locked]
    assert locked and 'aborted' in locked[0].reason and 'reach' in locked[0].reason
    returning = [o for o in outs if o.state == State.RETURN_TO_START]
    assert returning and returning[0].previous_state == State.FINAL_APPROACH


# ------------------------------------------------------------------------- locks, watchdog
def test_no_lock_into_and_out_of_center(fsm: GraspFsm) -> None:
    dwell = fsm.params.bci_select_dwell + 0.04                   # dwell, then select
    outs, _ = run(fsm, 0.0, dwell, cls=MiClass.BOTH_HANDS, obs=CENTRED)
    assert outs[-1].state == State.CENTER_OBJECT and not any(o.locked for o in outs)


def test_lock_holds_all_joints_for_lock_duration(fsm: GraspFsm) -> None:
    fsm.force_state(State.INITIAL_APPROACH)
    outs, _ = run(fsm, 0.0, 0.8, cls=MiClass.LEFT_HAND, obs=BIG)
    locked = [o for o in outs if o.locked]
    assert len(locked) == pytest.approx(0.5 / 0.02, abs=2)
    assert all(o.state == State.INITIAL_APPROACH for o in locked)
    assert all(np.all(o.joint_velocities == 0) for o in locked)
    assert outs[-1].state == State.FINAL_APPROACH


@pytest.mark.parametrize(('kw', 'match'), [
    ({'joints': 'stale'}, r'joint states are 0\.50 s old'),
    ({'joints': 'nan'}, r'NaN'),
    ({'joints': None}, r'no joint states'),
    ({'prediction': 'stale'}, r'MI prediction is 0\.50 s old'),
    ({'prediction': None}, r'no MI prediction'),
    ({'vision': 'stale'}, r'no camera images for 0\.80 s'),
    ({'vision': None}, r'no camera images received'),
])
def test_watchdog_stops_every_joint(fsm: GraspFsm, kw: dict, match: str) -> None:
    fsm.tick(inputs(0.0, cls=MiClass.LEFT_HAND, obs=None))
    good = inputs(1.0, cls=MiClass.LEFT_HAND, obs=None)
    assert fsm.tick(good).joint_velocities[0] > 0
    t = 1.02
    bad = inputs(t, cls=MiClass.LEFT_HAND, obs=None)
    if 'joints' in kw:
        if kw['joints'] == 'stale':
            bad.joints = JointStateIn(HOME, np.zeros(6), t - 0.5)
        elif kw['joints'] == 'nan':
            q = HOME.copy()
            q[2] = np.nan
            bad.joints = JointStateIn(q, np.zeros(6), t)
        else:
            bad.joints = None
    if 'prediction' in kw:
        bad.prediction = (None if kw['prediction'] is None
                          else type(good.prediction)(MiClass.LEFT_HAND, 1.0, t - 0.5))
    if 'vision' in kw:
        bad.vision = None if kw['vision'] is None else type(good.vision)(t - 0.8, 128, 128)
    out = fsm.tick(bad)
    assert out.stopped
    assert np.all(out.joint_velocities == 0)
    assert re.search(match, out.reason), out.reason
    # a missing first input is how a start begins; anything else is a fault (its log severity)
    missing = None in kw.values()
    assert out.stop_kind == (StopKind.AWAITING_INPUT if missing else StopKind.FAULT)
    # recovers when the inputs are good again (after a prediction loss or a joint-state fault,
    # which latches: a fresh decision first, tested below)
    if 'joints' in kw and kw['joints'] is not None:
        fsm.params.sensor_clean_time = 0.0
    if kw in ({'prediction': 'stale'}, {'joints': 'stale'}, {'joints': 'nan'}):
        fsm.params.resume_after_stale = 'resume'
    assert not fsm.tick(inputs(t + 0.02, cls=MiClass.LEFT_HAND, obs=None)).stopped


@pytest.mark.parametrize('fault', ['nan', 'inf', 'stale', 'refused'])
def test_a_joint_state_fault_latches_a_stop_until_clean_and_a_fresh_decision(
        fsm: GraspFsm, fault: str) -> None:
    """A NaN publisher beside the arm driver (issue 31, item 6): clean and faulty joint states
    alternate; the arm stays stopped until they were clean for sensor_clean_time (1 s) and then
    until a fresh decision, as after a prediction loss. One event when the latch starts, one
    when it is released."""
    outs, t = run(fsm, 0.0, 0.3, cls=MiClass.LEFT_HAND, obs=None)
    assert outs[-1].joint_velocities[0] > 0
    outs = []
    for k in range(80):                  # 1.6 s: every 3rd joint state is faulty
        t += 0.02
        inp = inputs(t, cls=MiClass.LEFT_HAND, obs=None)
        if k % 3 == 0 and fault in ('nan', 'inf'):
            q = HOME.copy()
            q[1] = np.nan if fault == 'nan' else np.inf
            inp.joints = JointStateIn(q, np.zeros(6), t)
        elif k % 3 == 0 and fault == 'stale':
            inp.joints = JointStateIn(HOME, np.zeros(6), t - 0.5)
        elif fault == 'refused':       # the node refused a message (wrong names or sizes)
            inp.joint_fault = (t - 0.02 * (k % 3), '/joint_states has 5 names')
        outs.append(fsm.tick(inp))
    assert all(o.stopped and not o.joint_velocities.any() for o in outs)
    events = [e for o in outs for e in o.events]
    assert len([e for e in events if e.startswith('sensor fault:')]) == 1, events
    # clean from now on, the person still imagines left hand: no move for sensor_clean_time,
    # then the release, then a fresh decision (resume_hold 1 s of predictions after it)
    outs, t = run(fsm, t + 0.02, 3.0, cls=MiClass.LEFT_HAND, obs=None)
    first = next(i for i, o in enumerate(outs) if not o.stopped)
    released = next(i for i, o in enumerate(outs)
                    if any(e.startswith('sensor fault released') for e in o.events))
    assert 0.9 <= released * 0.02 <= 1.1, released
    assert 'waiting for a new command' in outs[released + 1].reason
    assert 1.9 <= first * 0.02 <= 2.2, first
    assert any('fresh decision after the sensor fault' in e for e in outs[first].events)
    assert outs[-1].joint_velocities[0] > 0


def test_autonomous_mode_resumes_after_a_clean_sensor_time(params: FsmParams) -> None:
    params.autonomous = True
    fsm = GraspFsm.from_params(params)
    run(fsm, 0.0, 0.2, cls=None, obs=None)
    bad = inputs(0.22, cls=None, obs=None)
    bad.joint_fault = (0.21, '/joint_states has 5 names')
    assert fsm.tick(bad).stopped
    outs, _ = run(fsm, 0.24, 1.2, cls=None, obs=None)
    first = next(i for i, o in enumerate(outs) if not o.stopped)
    assert 0.9 <= 0.24 + first * 0.02 - 0.21 <= 1.05


@pytest.mark.parametrize(('state', 'outcome'), [(State.OBJECT_SEARCH, ''),
                                                 (State.RETURN_TO_START, 'holding'),
                                                 (State.RETURN_TO_START, 'failed')])
def test_every_velocity_profile_respects_the_acceleration_limits(state: State,
                                                                 outcome: str) -> None:
    """Issue 31, item 7: no command speeds a joint up faster than max_joint_acceleration, nor
    than return_acceleration in state 6 (the return used to jump 0.02 -> 0.5 rad/s in a tick
    after the lift), on a kinematic arm that follows the commands."""
    params = FsmParams(lock_duration=0.5, paradigm='paper', autonomous=True)
    fsm = GraspFsm.from_params(params)
    fsm._outcome = outcome
    fsm.force_state(state)
    q = HOME.copy()
    q[1] += 0.6
    q[2] -= 0.5
    prev, t, worst = np.zeros(6), 0.0, 0.0
    for _ in range(400):
        out = fsm.tick(inputs(t, q=q, cls=None, obs=None,
                              gripper=HOLDING if outcome == 'holding' else None))
        v = out.joint_velocities
        limit = params.return_acceleration if out.state == State.RETURN_TO_START else \
            max(params.max_joint_acceleration)
        speed_up = np.where(prev * v >= 0, np.abs(v) - np.abs(prev), np.abs(v))
        worst = max(worst, float(np.max(speed_up)) / 0.02 / limit)
        q = q + 0.02 * v
        prev, t = v, t + 0.02
    assert 0.5 < worst <= 1.0 + 1e-9


def test_acceleration_limiter_brakes_at_once_and_ramps_after_a_reversal() -> None:
    from mindgrasp_fsm.acceleration import AccelerationLimiter

    lim = AccelerationLimiter(2)
    np.testing.assert_allclose(lim.limit(np.array([1.0, -1.0]), 0.1, 2.0), [0.2, -0.2])
    np.testing.assert_allclose(lim.limit(np.array([1.0, -0.1]), 0.1, [2.0, 2.0]), [0.4, -0.1])
    np.testing.assert_allclose(lim.limit(np.array([-1.0, 0.0]), 0.1, 2.0), [-0.2, 0.0])
    np.testing.assert_allclose(lim.limit(np.array([-1.0, 0.0]), 0.0, 2.0), [-0.2, 0.0])


def test_after_a_prediction_loss_the_arm_waits_for_a_fresh_decision(fsm: GraspFsm) -> None:
    """resume_after_stale: require_new_command (default): predictions that come back do not move
    the arm until one class was decoded without a break for resume_hold (1 s)."""
    assert fsm.params.resume_after_stale == 'require_new_command'
    outs, t = run(fsm, 0.0, 0.5, cls=MiClass.LEFT_HAND, obs=None)
    assert outs[-1].joint_velocities[0] > 0                 # turning left
    lost = inputs(t + 0.5, cls=MiClass.LEFT_HAND, obs=None)
    lost.prediction = Prediction(MiClass.LEFT_HAND, 1.0, t)  # EEG lost: 0.5 s old
    assert fsm.tick(lost).stopped
    # the EEG is back and still decodes left hand: the arm does not start by itself
    outs, t = run(fsm, t + 0.52, 0.6, cls=MiClass.LEFT_HAND, obs=None)
    assert all(o.stopped and np.all(o.joint_velocities == 0) for o in outs)
    assert 'waiting for a new command' in outs[-1].reason
    # a change of class starts the count again
    outs, t = run(fsm, t, 0.6, cls=MiClass.RIGHT_HAND, obs=None)
    assert all(o.stopped for o in outs)
    # right hand held for 1 s in all: the fresh decision; the arm turns right
    outs, t = run(fsm, t, 0.5, cls=MiClass.RIGHT_HAND, obs=None)
    moving = [o for o in outs if not o.stopped]
    assert moving and moving[0].joint_velocities[0] < 0
    assert any('fresh decision' in e for o in outs for e in o.events)
    first = next(i for i, o in enumerate(outs) if not o.stopped)
    assert 0.35 <= first * 0.02 <= 0.45                     # 1.0 s after the class changed


def test_resume_after_stale_resume_goes_on_at_once(fsm: GraspFsm) -> None:
    fsm.params.resume_after_stale = 'resume'
    _, t = run(fsm, 0.0, 0.5, cls=MiClass.LEFT_HAND, obs=None)
    lost = inputs(t + 0.5, cls=MiClass.LEFT_HAND, obs=None)
    lost.prediction = Prediction(MiClass.LEFT_HAND, 1.0, t)
    assert fsm.tick(lost).stopped
    assert not fsm.tick(inputs(t + 0.52, cls=MiClass.LEFT_HAND, obs=None)).stopped


def test_resume_after_stale_must_be_a_known_mode(params: FsmParams) -> None:
    params.resume_after_stale = 'sometimes'
    with pytest.raises(FsmError, match="'resume_after_stale' is 'sometimes'; use one of "
                                       'require_new_command, resume'):
        params.validate()


def test_autonomous_mode_needs_no_predictions(params: FsmParams) -> None:
    params.autonomous = True
    fsm = GraspFsm.from_params(params)
    out = fsm.tick(inputs(0.0, cls=None, obs=None))
    assert not out.stopped
    assert out.joint_velocities[0] == pytest.approx(params.autonomous_search_velocity)


def test_watchdog_freezes_the_lock_timer(fsm: GraspFsm) -> None:
    fsm.force_state(State.INITIAL_APPROACH)
    fsm.tick(inputs(0.0, obs=BIG))              # lock begins
    stale = inputs(0.3, obs=BIG)
    stale.prediction = None
    for k in range(50):                          # 1 s without predictions
        stale.time = 0.3 + 0.02 * k
        stale.joints = JointStateIn(HOME, np.zeros(6), stale.time)
        stale.vision = inputs(stale.time, obs=BIG).vision
        assert fsm.tick(stale).stopped
    out = fsm.tick(inputs(1.4, obs=BIG))
    assert out.locked and out.state == State.INITIAL_APPROACH


def test_gripper_is_kept_while_stopped(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    out = fsm.tick(inputs(0.0, q=_grasp_pose(), obs=None, gripper=HOLDING))
    closed = out.gripper
    stale = inputs(0.02, q=_grasp_pose(), obs=None, gripper=HOLDING)
    stale.joints = None
    out = fsm.tick(stale)
    assert out.stopped and out.gripper == closed


def test_bad_time_raises(fsm: GraspFsm) -> None:
    from mindgrasp_fsm.errors import FsmError

    with pytest.raises(FsmError, match='finite seconds'):
        fsm.tick(FsmInputs(time=float('nan')))


# ------------------------------------------------------------------------- joint limits
def test_clamp_stops_at_the_limits() -> None:
    p = FsmParams()
    hi = np.asarray(p.joint_upper_limits)
    lo = np.asarray(p.joint_lower_limits)
    q = hi - p.joint_limit_margin
    v = clamp_to_limits(q, np.full(6, 0.5), p)
    np.testing.assert_array_equal(v, np.zeros(6))
    v = clamp_to_limits(q, np.full(6, -0.5), p)          # moving away from a limit is fine
    np.testing.assert_allclose(v, np.full(6, -0.5))
    v = clamp_to_limits(lo + 0.001, np.full(6, -5.0), p)
    assert np.all(v >= 0)
    # one period from the limit: the step lands exactly on the margin
    q = hi - p.joint_limit_margin - 0.004
    v = clamp_to_limits(q, np.full(6, 1.0), p)
    np.testing.assert_allclose(q + v * p.control_period, hi - p.joint_limit_margin)


def test_never_commands_beyond_limits_or_speed(params: FsmParams) -> None:
    rng = np.random.default_rng(3)
    lo = np.asarray(params.joint_lower_limits)
    hi = np.asarray(params.joint_upper_limits)
    vmax = np.asarray(params.max_joint_velocity)
    for state in State:
        fsm = GraspFsm.from_params(params)
        fsm.force_state(state)
        for k in range(40):
            q = rng.uniform(lo - 0.1, hi + 0.1)
            obs = observation(*rng.uniform(0, 128, 2), rng.uniform(0, 0.3), rng.uniform(0.1, 1))
            out = fsm.tick(inputs(0.02 * k, q=q, cls=int(rng.integers(4)),
                                  cert=rng.uniform(0, 5), obs=obs,
                                  gripper=GripperState(0.5, 1.0, 0.02 * k, True)))
            v = out.joint_velocities
            assert np.all(np.abs(v) <= vmax + 1e-12)
            nxt = q + v * params.control_period
            over = (nxt > hi - params.joint_limit_margin + 1e-9) & (v > 0)
            under = (nxt < lo + params.joint_limit_margin - 1e-9) & (v < 0)
            assert not np.any(over | under), (state, q, v)


def test_object_beyond_the_joint1_limit_is_searched_the_other_way(params: FsmParams) -> None:
    params.autonomous = True
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.CENTER_OBJECT, center_next=State.INITIAL_APPROACH)
    q = HOME.copy()
    q[0] = params.joint_upper_limits[0] - params.joint_limit_margin - 0.01
    left = observation(20, 64)          # left of centre: centring would turn joint 1 further up
    out = fsm.tick(inputs(0.0, q=q, cls=None, obs=left))
    assert out.state == State.OBJECT_SEARCH and 'joint 1 is at its limit' in out.reason
    # the sweep now turns right and ignores the object it could not reach this way round
    out = fsm.tick(inputs(0.5, q=q, cls=None, obs=left))
    assert out.state == State.OBJECT_SEARCH
    assert out.joint_velocities[0] == pytest.approx(-params.autonomous_search_velocity)
    q[0] -= params.search_ignore_angle + 0.1
    for k in range(20):
        out = fsm.tick(inputs(1.0 + 0.02 * k, q=q, cls=None, obs=left))
    assert out.state == State.CENTER_OBJECT


def test_bci_does_not_reselect_an_object_it_could_not_centre(params: FsmParams) -> None:
    """Found in the demo: both-hands MI re-selected an object beyond the joint-1 limit on every
    tick, flipping between states 1 and 2 at the control rate."""
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.CENTER_OBJECT, center_next=State.INITIAL_APPROACH)
    q = HOME.copy()
    q[0] = params.joint_upper_limits[0] - params.joint_limit_margin - 0.01
    left = observation(20, 64)
    out = fsm.tick(inputs(0.0, q=q, cls=MiClass.BOTH_HANDS, obs=left))
    assert out.state == State.OBJECT_SEARCH and 'joint 1 is at its limit' in out.reason
    outs, t = run(fsm, 0.02, params.bci_reselect_delay - 0.1, q=q, cls=MiClass.BOTH_HANDS,
                  obs=left)
    assert all(o.state == State.OBJECT_SEARCH for o in outs)
    assert 'turn left or right' in outs[-1].phase
    q[0] -= params.bci_reselect_angle + 0.05  # the user turned right: it may be selected again
    out = fsm.tick(inputs(t, q=q, cls=MiClass.BOTH_HANDS, obs=left))
    assert out.state == State.CENTER_OBJECT


def test_search_opens_a_gripper_closed_on_nothing(params: FsmParams) -> None:
    """Found in the demo: after a scene reset the hand stayed closed and its fingers hid the
    next object from the camera."""
    fsm = GraspFsm.from_params(params)
    fsm._gripper = GripperCommand(1.0, 20.0)
    holding = GripperState(0.3, 5.0, 0.0, contact=True, fingers_in_contact=3)
    out = fsm.tick(inputs(0.0, cls=MiClass.LEFT_HAND, cert=0.0, gripper=holding))
    assert out.state == State.OBJECT_SEARCH and out.gripper.position == 1.0  # still holding
    empty = GripperState(0.0, 0.0, 0.02, contact=False, fingers_in_contact=0)
    out = fsm.tick(inputs(0.02, cls=MiClass.LEFT_HAND, cert=0.0, gripper=empty))
    assert out.gripper.position == params.gripper_open_position


def test_centring_timeout_far_off_centre_searches_again(params: FsmParams) -> None:
    params.center_timeout = 0.3
    params.center_gain_joint1 = 0.0     # a centring that gets nowhere
    fsm = GraspFsm.from_params(params)
    fsm.force_state(State.CENTER_OBJECT, center_next=State.INITIAL_APPROACH)
    outs, _ = run(fsm, 0.0, 0.5, cls=MiClass.BOTH_FEET, obs=observation(64 + 0.3 * 128, 64))
    assert outs[-1].state == State.OBJECT_SEARCH
    assert 'could not be centred' in outs[-1].reason


def test_two_finger_grasp_is_not_firm_enough(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    two = GripperState(opening=0.6, force=float('nan'), stamp=0.0, contact=True,
                       fingers_in_contact=2)
    outs, _, _ = _drive(fsm, _grasp_pose(), two, 8.0)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and 'only 2 finger(s) touch the object' in entered[0].reason


def test_carrying_return_rises_first_and_moves_gently(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    three = GripperState(opening=0.6, force=float('nan'), stamp=0.0, contact=True,
                         fingers_in_contact=3)
    outs, q, _ = _drive(fsm, _grasp_pose(), three, 25.0)
    ret = [o for o in outs if o.state == State.RETURN_TO_START and not o.locked]
    assert ret and ret[0].phase == 'lifting'
    assert 'returning' in {o.phase for o in ret}
    assert max(float(np.max(np.abs(o.joint_velocities))) for o in ret) \
        <= params.return_velocity_holding + 1e-9
    first_return = next(i for i, o in enumerate(ret) if o.phase == 'returning')
    assert first_return > 0
    assert outs[-1].state == State.OBJECT_SEARCH   # arrived home
    np.testing.assert_allclose(q, HOME, atol=params.return_tolerance)


#: a real hand closed on the table beside the object: every finger "in contact" (the table), but
#: the finger motors barely loaded; and one squeezing the object (efforts at the motor limits)
ON_TABLE = GripperState(opening=0.5, force=0.25, stamp=0.0, contact=True, fingers_in_contact=3,
                        efforts=(0.09, 0.08, 0.08))
SQUEEZING = GripperState(opening=0.5, force=4.8, stamp=0.0, contact=True, fingers_in_contact=3,
                         efforts=(2.4, -1.2, -1.2))


def test_grasp_check_counts_fingers_loaded_by_effort(params: FsmParams) -> None:
    """Contact on any surface is not a grasp: the check uses finger efforts when the hand
    reports them, and lifts before deciding."""
    fsm = _grasp_fsm(params)
    outs, _, _ = _drive(fsm, _grasp_pose(), ON_TABLE, 8.0)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and '0 finger(s) push on something' in entered[0].reason
    fsm = _grasp_fsm(params)
    outs, _, _ = _drive(fsm, _grasp_pose(), SQUEEZING, 8.0)
    assert fsm.outcome == 'holding'
    assert {'lift', 'check_lift'} <= {o.phase for o in outs}


#: open fingertips pressed on the table (a live arm a few mm low): the motors loaded, the
#: fingers not closed (seen live with real rclpy on a loaded machine)
OPEN_ON_TABLE = GripperState(opening=0.95, force=1.2, stamp=0.0, contact=False,
                             fingers_in_contact=0, efforts=(1.02, -1.2, -1.09))


def test_a_load_before_the_fingers_close_is_not_contact(params: FsmParams) -> None:
    """The closing holds at the contact point only once the fingers travelled
    ``contact_min_travel`` since it began: loaded open fingertips (the table) are not the
    object, and holding there (closure 0.15) lifted nothing. Once they close on the object
    the hold is set from there."""
    fsm = _grasp_fsm(params)
    q = _grasp_pose()
    outs, q, t = _drive(fsm, q, OPEN_ON_TABLE, 0.2)
    assert {o.phase for o in outs} == {'close'}
    assert all(o.gripper.position == params.gripper_closed_position for o in outs)
    outs, _, _ = _drive(fsm, q, SQUEEZING, 1.0, t0=t)
    held = [o.gripper.position for o in outs if o.gripper.position < params.gripper_closed_position]
    assert held and held[0] == pytest.approx(1.0 - SQUEEZING.opening + params.grip_squeeze)
    assert 'lift' in {o.phase for o in outs}


def test_object_lost_in_the_lift_unloads_the_fingers(params: FsmParams) -> None:
    fsm = _grasp_fsm(params)
    q = _grasp_pose()
    outs, q, t = _drive(fsm, q, SQUEEZING, 1.2)
    assert outs[-1].phase == 'lift'
    outs, _, _ = _drive(fsm, q, ON_TABLE, 6.0, t0=t)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and 'slipped after the lift' in entered[0].reason


def test_an_object_carried_by_two_fingers_after_the_lift_is_held(params: FsmParams) -> None:
    """Three fingers must close on the object; after the lift two that still carry it are a
    hold (a sphere off-centre in the hand), one is a slip."""
    two = GripperState(opening=0.5, force=2.6, stamp=0.0, contact=True, fingers_in_contact=2,
                       efforts=(1.35, 1.21, 0.07))
    one = GripperState(opening=0.5, force=1.4, stamp=0.0, contact=True, fingers_in_contact=1,
                       efforts=(1.35, 0.1, 0.07))
    for after_lift, outcome in ((two, 'holding'), (one, None)):
        fsm = _grasp_fsm(params)
        q = _grasp_pose()
        outs, q, t = _drive(fsm, q, SQUEEZING, 1.2)
        assert outs[-1].phase == 'lift'
        outs, _, _ = _drive(fsm, q, after_lift, 6.0, t0=t)
        if outcome:
            assert fsm.outcome == outcome
        else:
            entered = [o for o in outs if o.state == State.FINAL_APPROACH]
            assert entered and '1 finger(s) push on something' in entered[0].reason


#: a parallel-jaw gripper (the xArm's): six linkage joints, only the drive joint has a motor
JAWS_ON_OBJECT = GripperState(opening=0.45, force=2.0, stamp=0.0, contact=False,
                              fingers_in_contact=0, efforts=(2.0, 0.0, 0.0, 0.0, 0.0, 0.0))
JAWS_SHUT = GripperState(opening=0.0, force=0.01, stamp=0.0, contact=False, fingers_in_contact=0,
                         efforts=(0.01, 0.0, 0.0, 0.0, 0.0, 0.0))


def test_width_check_holds_on_jaws_stopped_apart(params: FsmParams) -> None:
    """grasp_check width (a parallel-jaw gripper's description): the jaws stopping apart on
    the full closing command is a grasp (its one motor is the only loaded joint, which the
    effort check took for a one-finger touch); jaws closing through after the lift are a slip."""
    width = dataclasses.replace(params, grasp_check='width')
    fsm = _grasp_fsm(width)
    outs, q, t = _drive(fsm, _grasp_pose(), JAWS_ON_OBJECT, 1.2)
    assert outs[-1].phase == 'lift'
    # the jaws keep the full closing command (no squeeze hold just past the contact)
    assert outs[-1].gripper.position == width.gripper_closed_position
    outs, _, _ = _drive(fsm, q, JAWS_SHUT, 6.0, t0=t)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and 'slipped after the lift: fingers closed on nothing' in entered[0].reason
    fsm = _grasp_fsm(width)
    _drive(fsm, _grasp_pose(), JAWS_ON_OBJECT, 8.0)
    assert fsm.outcome == 'holding'
    fsm = _grasp_fsm(params)                  # the effort check counts one loaded finger
    outs, _, _ = _drive(fsm, _grasp_pose(), JAWS_ON_OBJECT, 8.0)
    entered = [o for o in outs if o.state == State.FINAL_APPROACH]
    assert entered and '1 finger(s) push on something' in entered[0].reason


def test_contact_flags_are_used_without_efforts_or_when_asked(params: FsmParams) -> None:
    from mindgrasp_fsm.grasp_policy import fingers_loaded

    assert fingers_loaded(SQUEEZING, 0.4) == 3 and fingers_loaded(ON_TABLE, 0.4) == 0
    assert fingers_loaded(HOLDING, 0.4) is None            # no efforts reported
    assert fingers_loaded(SQUEEZING, 0.0) is None          # finger_contact_effort: 0
    fsm = _grasp_fsm(dataclasses.replace(params, finger_contact_effort=0.0))
    _drive(fsm, _grasp_pose(), ON_TABLE, 8.0)
    assert fsm.outcome == 'holding'                        # a simulator's contact flags


def test_a_measurement_is_the_median_of_several_frames(params: FsmParams) -> None:
    """A noisy camera: one measurement takes ``measure_frames`` frames, an outlier frame (a
    depth drop-out, a mis-segmented box) does not move the estimate."""
    from mindgrasp_fsm.grasp_policy import GraspPolicy

    from .conftest import CAMERA, frame

    fsm = GraspFsm.from_params(params)
    kin = fsm.kinematics

    def measured(frames: list) -> np.ndarray:
        policy = GraspPolicy(dataclasses.replace(params, measure_frames=len(frames)), kin)
        policy.begin_approach(0.0, 'cube', 0)
        policy.phase = 'measure'
        t = 1.0
        for obs in frames:
            step = policy.approach_step(t, HOME, frame(t, obs), CAMERA, None)
            assert policy.object_position is None or step.phase == 'to_pregrasp'
            t += 0.1
        assert policy.phase == 'to_pregrasp'
        return policy.object_position

    good = observation(64, 70, distance=0.6)
    single = measured([good])
    noisy = measured([observation(62, 71, distance=0.61), good,
                      observation(90, 40, distance=0.3)])   # an outlier frame
    np.testing.assert_allclose(noisy[:2], single[:2], atol=0.01)
    repeated = measured([good, good, good])
    np.testing.assert_allclose(repeated, single)


def test_an_object_of_unknown_shape_is_named_by_its_colour() -> None:
    """Before the depth CNN names the shape, logs and /fsm/state said "yellow unknown"."""
    fsm = GraspFsm.from_params(FsmParams())       # the default paradigm scans for objects
    outs, _ = run(fsm, 0.0, 3.0, cls=MiClass.BOTH_HANDS,
                  obs=observation(shape='unknown', colour='yellow'))
    reasons = [o.reason for o in outs]
    assert any('yellow object seen by the' in r for r in reasons), reasons
    assert not any('unknown' in r for r in reasons), reasons
    assert 'yellow object' in {o.object_of_interest for o in outs}
    assert observation(shape='cylinder', colour='red').label == 'red cylinder'
