"""MIndGrasp Trainer protocol: timing, motion directions, reset rule, distance metric."""

from __future__ import annotations

import collections
import math

import numpy as np
import pytest

from mindgrasp_trainer.protocol import NO_CLASS, TrainerError
from mindgrasp_trainer.trainer import TrainerProtocol, ee_distance

DT = 0.01


def run(proto: TrainerProtocol, t_end: float, z=lambda t: 0.5, fsm=lambda t: 1):
    """Drive the protocol on a 10 ms clock; return (times, commands, events, resets)."""
    events = proto.start(0.0)
    times, commands, resets = [], [], []
    t = 0.0
    while t < t_end and not proto.done:
        t = round(t + DT, 6)
        step = proto.update(t, trainer_ee_z=z(t), fsm_state=fsm(t))
        times.append(t)
        commands.append(step.command)
        events.extend(step.events)
        if step.reset:
            resets.append((t, step.reset))
            proto.reset_finished(t + 0.2)  # the reset service answers 0.2 s later
    return np.array(times), np.array(commands), events, resets


def test_directions_per_class():
    proto = TrainerProtocol(turn_speed=0.2, approach_speed=0.05)
    np.testing.assert_allclose(proto.velocity(0), [0.2, 0, 0, 0, 0, 0])  # left: joint 1 +
    np.testing.assert_allclose(proto.velocity(1), [-0.2, 0, 0, 0, 0, 0])  # right: joint 1 -
    np.testing.assert_allclose(proto.velocity(2), [0, 0.05, 0, 0, 0, 0])  # approach: joint 2 +
    np.testing.assert_allclose(proto.velocity(3), [0, -0.05, 0, 0, 0, 0])  # back away: joint 2 -
    np.testing.assert_allclose(proto.velocity(NO_CLASS), np.zeros(6))
    with pytest.raises(TrainerError, match='Class index 7 is not a motor-imagery class'):
        proto.velocity(7)


def test_move_two_seconds_then_wait_two_seconds():
    proto = TrainerProtocol(n_trials=8, seed=4)
    times, commands, events, resets = run(proto, 100.0)
    assert not resets and proto.done
    phases = [e.phase for e in events]
    assert phases == ['move', 'wait'] * 8 + ['end']
    for i in range(8):
        move, wait = events[2 * i], events[2 * i + 1]
        assert move.onset == pytest.approx(4.0 * i) and move.duration == 2.0
        assert wait.onset == pytest.approx(4.0 * i + 2.0) and wait.duration == 2.0
        assert move.class_index == wait.class_index == proto.order[i]
        assert move.trial == wait.trial == i + 1
        # the robot moves only during the move phase, with that class's velocity
        in_move = (times > move.onset + 1e-6) & (times < move.onset + 2.0 - 1e-6)
        in_wait = (times > wait.onset + 1e-6) & (times < wait.onset + 2.0 - 1e-6)
        np.testing.assert_allclose(commands[in_move], proto.velocity(move.class_index)[None].repeat(
            in_move.sum(), 0))
        assert not commands[in_wait].any()
    assert events[-1].onset == pytest.approx(32.0) and events[-1].class_index == NO_CLASS
    # joint 1 turned for 2 s per left/right trial
    turn = commands[:, 0].sum() * DT
    n_left = int((proto.order == 0).sum())
    n_right = int((proto.order == 1).sum())
    assert turn == pytest.approx(0.2 * 2.0 * (n_left - n_right), abs=0.01)


def test_balanced_and_seeded_order():
    a = TrainerProtocol(n_trials=40, seed=1).order
    b = TrainerProtocol(n_trials=40, seed=1).order
    c = TrainerProtocol(n_trials=40, seed=2).order
    np.testing.assert_array_equal(a, b)
    assert (a != c).any()
    assert collections.Counter(a.tolist()) == {k: 10 for k in range(4)}
    # the paper's independent draw: same seed same order, all four classes present
    u = TrainerProtocol(n_trials=40, seed=1, balanced=False).order
    np.testing.assert_array_equal(u, TrainerProtocol(n_trials=40, seed=1, balanced=False).order)
    assert set(u.tolist()) == {0, 1, 2, 3}


def test_reset_when_training_end_effector_below_0_1_m():
    proto = TrainerProtocol(n_trials=3, seed=0, settle_time=1.0)
    # the end-effector sinks below 0.1 m at t = 5.0 s (during trial 2's move)
    times, commands, events, resets = run(proto, 100.0, z=lambda t: 0.05 if 5.0 <= t < 5.3 else 0.3)
    assert len(resets) == 1
    t_reset, reason = resets[0]
    assert t_reset == pytest.approx(5.0) and 'below 0.100 m' in reason
    assert [e.phase for e in events] == ['move', 'wait', 'move', 'rest', 'move', 'wait', 'end']
    rest = events[3]
    assert rest.class_index == NO_CLASS and rest.onset == pytest.approx(5.0)
    # next trial: reset answered at 5.2 s, plus 1 s settle
    assert events[4].onset == pytest.approx(6.2) and events[4].trial == 3
    assert proto.trials[1].aborted.startswith('training end-effector at 0.0500 m')
    # the robot stops at once when the reset fires and stays still until the next trial
    still = (times >= 5.0 - 1e-9) & (times < 6.2 - 1e-9)
    assert not commands[still].any()
    assert proto.summary()['n_resets'] == 1 and proto.summary()['n_aborted'] == 1


def test_low_end_effector_is_ignored_while_settling():
    proto = TrainerProtocol(n_trials=2, seed=0, settle_time=1.0)
    # stays low during the reset and the settle time; only one reset
    _, _, _, resets = run(proto, 100.0, z=lambda t: 0.05 if 1.0 <= t < 2.1 else 0.3)
    assert len(resets) == 1


def test_reset_when_user_robot_enters_grasp_state():
    proto = TrainerProtocol(n_trials=4, seed=0)
    # FSM: searching, then GRASP_OBJECT (5) from 9.5 s on; it stays there for a while
    _times, _, events, resets = run(proto, 100.0, fsm=lambda t: 5 if 9.5 <= t < 14.0 else 1)
    assert len(resets) == 1  # entering fires once, staying does not fire again
    assert resets[0][0] == pytest.approx(9.5) and 'grasp state' in resets[0][1]
    assert proto.trials[2].aborted == "user's robot entered the grasp state"
    assert [e.phase for e in events].count('rest') == 1


def test_grasp_state_at_start_does_not_fire():
    proto = TrainerProtocol(n_trials=2, seed=0)
    _, _, _, resets = run(proto, 100.0, fsm=lambda t: 5)
    assert resets == []


def test_duration_ends_the_session_early():
    proto = TrainerProtocol(n_trials=40, seed=0, duration=9.0)
    _times, commands, events, _ = run(proto, 100.0)
    assert proto.done and events[-1].phase == 'end'
    assert events[-1].onset == pytest.approx(9.0)
    assert not commands[-1].any()
    assert proto.trials[-1].aborted == 'duration'


def test_start_delay_rests_first():
    proto = TrainerProtocol(n_trials=1, start_delay=1.5)
    _, _, events, _ = run(proto, 100.0)
    assert [e.phase for e in events] == ['rest', 'move', 'wait', 'end']
    assert events[1].onset == pytest.approx(1.5)


def test_late_update_does_not_skip_phases():
    proto = TrainerProtocol(n_trials=2, seed=0)
    proto.start(10.0)
    step = proto.update(20.0)
    # move(10) -> wait(12) -> move(14) -> wait(16) -> end(18), all with their planned onsets
    assert [e.phase for e in step.events] == ['wait', 'move', 'wait', 'end']
    assert [e.onset for e in step.events] == pytest.approx([2.0, 4.0, 6.0, 8.0])
    assert step.done


def test_distance_metric():
    assert ee_distance([0, 0, 0], [0.3, 0.4, 0]) == pytest.approx(0.5)
    with pytest.raises(TrainerError, match='End-effector positions need 3 coordinates'):
        ee_distance([0, 0], [0, 0, 0])
    proto = TrainerProtocol(n_trials=2, seed=0)
    proto.start(0.0)
    for d in (0.1, 0.2, 0.3):
        proto.record_distance(d)
    proto.update(4.5)
    proto.record_distance(0.5)
    proto.record_distance(math.nan)  # ignored
    s = proto.summary()
    assert proto.trials[0].mean_distance == pytest.approx(0.2)
    assert proto.trials[0].final_distance == pytest.approx(0.3)
    assert proto.trials[1].mean_distance == pytest.approx(0.5)
    assert s['mean_ee_distance'] == pytest.approx(0.275)
    assert s['mean_final_ee_distance'] == pytest.approx(0.4)
    k0 = proto.trials[0].class_name
    assert s['per_class_ee_distance'][k0] == pytest.approx(0.2)


@pytest.mark.parametrize(
    ('kwargs', 'match'),
    [
        ({'move_duration': 0}, "duration 'move_duration' must be a finite number"),
        ({'wait_duration': -1}, "duration 'wait_duration'"),
        ({'settle_time': float('inf')}, "duration 'settle_time'"),
        ({'turn_joint': 6}, "'turn_joint' is 6, outside the 6 joints; use an index from 0 to 5"),
        ({'approach_speed': float('nan')}, "'approach_speed' must be finite"),
        ({'n_trials': 0}, "'n_trials' must be at least 1"),
        ({'n_trials': 0, 'balanced': False}, "'n_trials' must be at least 1"),
        ({'classes': [5]}, 'not class indices'),
    ],
)
def test_bad_parameters(kwargs, match):
    with pytest.raises(TrainerError, match=match):
        TrainerProtocol(**kwargs)


def test_update_before_start_and_double_start():
    proto = TrainerProtocol()
    with pytest.raises(TrainerError, match=r'called before start\(\); call start\(t\) first'):
        proto.update(0.0)
    proto.start(0.0)
    with pytest.raises(TrainerError, match='already started'):
        proto.start(1.0)
