"""Graz-BCI schedule: timing, balance, determinism per seed, bad parameters."""

from __future__ import annotations

import collections
import itertools

import numpy as np
import pytest

from mindgrasp_trainer.graz import GrazProtocol, PromptSequencer
from mindgrasp_trainer.protocol import NO_CLASS, TrainerError, balanced_order


def test_trial_structure_and_timing():
    proto = GrazProtocol(n_trials=8, seed=3, start_delay=0.5)
    events = proto.schedule()
    assert len(events) == 4 * 8 + 1
    assert events[-1].phase == 'end' and events[-1].class_index == NO_CLASS
    assert events[0].onset == pytest.approx(0.5)
    for i in range(8):
        fix, cue, move, rest = events[4 * i : 4 * i + 4]
        assert [e.phase for e in (fix, cue, move, rest)] == ['fixation', 'cue', 'move', 'rest']
        assert {e.trial for e in (fix, cue, move, rest)} == {i + 1}
        assert fix.duration == pytest.approx(2.0) and cue.duration == pytest.approx(1.25)
        assert move.duration == pytest.approx(2.75)
        assert 1.5 <= rest.duration <= 2.5
        # cue and move ask for the same class; fixation and rest for none
        assert cue.class_index == move.class_index != NO_CLASS
        assert fix.class_index == rest.class_index == NO_CLASS
        assert cue.class_name == ('left_hand', 'right_hand', 'both_hands', 'both_feet')[
            cue.class_index
        ]
        # phases are contiguous: each onset is the previous onset plus its duration
        for a, b in zip((fix, cue, move, rest), (cue, move, rest, events[4 * i + 4]), strict=True):
            assert b.onset == pytest.approx(a.onset + a.duration)
        # imagery lasts 4 s from cue onset (BCI Competition IV 2a)
        assert rest.onset - cue.onset == pytest.approx(4.0)
    assert proto.total_duration() == pytest.approx(events[-1].onset)


@pytest.mark.parametrize('n_per_class', [1, 5, 18])
def test_balanced_classes(n_per_class):
    order = GrazProtocol(n_trials=4 * n_per_class, seed=11).class_order()
    assert collections.Counter(order.tolist()) == {k: n_per_class for k in range(4)}


def test_uneven_count_differs_by_at_most_one_and_subset_of_classes():
    order = GrazProtocol(n_trials=7, classes=(0, 1), seed=2).class_order()
    counts = collections.Counter(order.tolist())
    assert set(counts) == {0, 1} and abs(counts[0] - counts[1]) == 1


def test_same_seed_same_schedule_other_seed_other_schedule():
    a = GrazProtocol(n_trials=40, seed=7).schedule()
    b = GrazProtocol(n_trials=40, seed=7).schedule()
    c = GrazProtocol(n_trials=40, seed=8).schedule()
    assert a == b
    assert [e.class_index for e in a] != [e.class_index for e in c]
    assert [e.duration for e in a] != [e.duration for e in c]


def test_rest_range_does_not_change_class_order():
    a = GrazProtocol(n_trials=20, seed=5).class_order()
    b = GrazProtocol(n_trials=20, seed=5, rest_min=0.5, rest_max=0.6).class_order()
    np.testing.assert_array_equal(a, b)


def test_rests_are_spread_over_the_range():
    rests = [e.duration for e in GrazProtocol(n_trials=200, seed=1).schedule() if e.phase == 'rest']
    assert min(rests) < 1.6 and max(rests) > 2.4
    assert np.mean(rests) == pytest.approx(2.0, abs=0.08)


@pytest.mark.parametrize('max_repeat', [1, 2])
def test_max_repeat_limits_runs(max_repeat):
    for seed in range(20):
        order = balanced_order(40, (0, 1, 2, 3), np.random.default_rng(seed), max_repeat)
        assert collections.Counter(order.tolist()) == {k: 10 for k in range(4)}
        run = 1
        for a, b in itertools.pairwise(order):
            run = run + 1 if a == b else 1
            assert run <= max_repeat


def test_unconstrained_order_has_runs():
    # without the limit, runs of 3+ occur in 40 trials for some seeds (plain shuffle)
    longest = 0
    for seed in range(20):
        order = balanced_order(40, (0, 1, 2, 3), np.random.default_rng(seed))
        run = 1
        for a, b in itertools.pairwise(order):
            run = run + 1 if a == b else 1
            longest = max(longest, run)
    assert longest >= 3


def test_impossible_max_repeat_is_reported():
    # one class cannot alternate; two classes with counts 3 and 2 can (ABABA)
    with pytest.raises(TrainerError, match="keeps runs to 1; raise 'max_repeat' or add classes"):
        balanced_order(3, (2,), np.random.default_rng(0), 1)
    order = balanced_order(5, (0, 1), np.random.default_rng(0), 1)
    assert all(a != b for a, b in itertools.pairwise(order))


@pytest.mark.parametrize(
    ('kwargs', 'match'),
    [
        ({'classes': ()}, "'classes' is empty"),
        ({'classes': (0, 4)}, r"holds \[4\], which are not class indices"),
        ({'classes': (1, 1)}, 'has duplicates'),
        ({'n_trials': 0}, "'n_trials' must be at least 1; 0 is invalid"),
        ({'cue': 0}, "duration 'cue' must be a finite positive number of seconds; 0.0"),
        ({'fixation': float('nan')}, "duration 'fixation' must be a finite positive"),
        ({'rest_min': -1}, "'rest_min' must be a finite zero or positive"),
        ({'rest_min': 3.0, 'rest_max': 2.0}, "'rest_min' .3.0 s. is larger than 'rest_max'"),
        ({'max_repeat': -1}, "'max_repeat' must be 0"),
    ],
)
def test_bad_parameters(kwargs, match):
    with pytest.raises(TrainerError, match=match):
        GrazProtocol(**kwargs).schedule()


def test_sequencer_hands_out_events_once_in_order():
    events = GrazProtocol(n_trials=4, seed=0).schedule()
    seq = PromptSequencer(events)
    got = []
    t = 0.0
    while not seq.done:
        got.extend(seq.due(t))
        t += 0.01
    assert got == events
    assert seq.due(1e9) == []
    # a late call hands out every missed event at once, in order
    seq2 = PromptSequencer(events)
    assert seq2.due(events[5].onset) == events[:6]
    assert seq2.current == events[5]


def test_sequencer_stop_ends_early():
    events = GrazProtocol(n_trials=4, seed=0).schedule()
    seq = PromptSequencer(events)
    seq.due(5.0)
    end = seq.stop(5.0)
    assert end.phase == 'end' and end.onset == 5.0 and end.trial == 1 and seq.done
    assert seq.stop(6.0) is None


def test_sequencer_rejects_unsorted():
    events = GrazProtocol(n_trials=4, seed=0).schedule()
    with pytest.raises(TrainerError, match='not in time order'):
        PromptSequencer(events[::-1])
    with pytest.raises(TrainerError, match='schedule is empty'):
        PromptSequencer([])
