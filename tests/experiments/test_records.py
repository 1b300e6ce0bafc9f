"""The one trial record: what a trial manager hears becomes a TrialRecord; CSV/Parquet round trip;
summary rates with Wilson intervals; protocol draws depend on (seed, trial) only."""

from __future__ import annotations

import math

import pytest

from mindgrasp_experiments.protocols import random_locations_trial, set_locations_target
from mindgrasp_experiments.records import (
    SUCCESS_HEIGHT,
    TrialRecord,
    TrialTracker,
    read_records,
    write_records,
)
from mindgrasp_experiments.summary import summarise, wilson


def _trial(tracker: TrialTracker, n: int, desired: str, chosen: str, grasped: str,
           success: bool) -> TrialRecord:
    tracker.start(n, desired, 0, t=10.0, desired_xy=(0.5, 0.0), state=1)
    tracker.on_intent('left_hand')
    tracker.on_prediction(0, 1.0, 10.1)
    tracker.on_prediction(2, 0.5, 10.2)        # a switch, and a miss against the intent
    tracker.on_ee_pose(0.0, 0.0, 0.3)
    tracker.on_ee_pose(0.3, 0.4, 0.3)          # 0.5 m
    for state in (2, 3, 4, 5):
        tracker.on_state(state, chosen, 11.0 + state)
    if grasped:
        tracker.on_result(grasped, success, 20.0, lift_height=0.25 if success else 0.1)
    return tracker.finish(25.0)


def test_tracker_builds_the_record() -> None:
    tracker = TrialTracker('set_locations', 'virtual', seed=3)
    rec = _trial(tracker, 1, 'red cube', 'red cube', 'red cube', True)
    assert rec.success and rec.correct_choice and rec.correct_and_successful
    assert rec.time_to_grasp_s == 10.0 and rec.duration_s == 15.0
    assert rec.states == '1-2-3-4-5' and rec.chosen == 'red cube'
    assert math.isclose(rec.path_length_m, 0.5)
    assert rec.class_switches == 1 and rec.n_predictions == 2
    assert rec.online_accuracy == 0.5 and rec.mean_certainty == 0.75
    assert rec.failure == '' and 'lifted above 0.22 m' in rec.reason
    assert (rec.protocol, rec.subject, rec.seed) == ('set_locations', 'virtual', 3)
    assert SUCCESS_HEIGHT == 0.22


def test_wrong_object_lifted_and_no_grasp() -> None:
    tracker = TrialTracker()
    wrong = _trial(tracker, 1, 'red cube', 'blue unknown', 'blue cylinder', True)
    assert wrong.success and not wrong.correct_choice and not wrong.correct_and_successful
    missed = _trial(tracker, 2, 'red cube', 'red unknown', '', False)
    assert not missed.success and missed.failure == 'no_grasp'
    # nothing lifted: the choice is judged by the controller's named object (colour + CNN shape)
    named = _trial(tracker, 3, 'red cube', 'red cube', '', False)
    assert named.correct_choice and not named.correct_and_successful
    with pytest.raises(ValueError, match="Unknown trial failure 'oops'"):
        tracker.start(4, 'red cube')
        tracker.finish(1.0, 'oops')
    with pytest.raises(RuntimeError, match='call start'):
        TrialTracker().finish(1.0)


def test_a_drop_does_not_end_the_trial_and_is_named() -> None:
    tracker = TrialTracker()
    tracker.start(1, 'red sphere', 0, t=0.0)
    tracker.on_result('red sphere', False, 10.0, lift_height=0.157)   # slipped out
    tracker.on_result('red sphere', True, 18.0, lift_height=0.25)     # the retry lifted it
    tracker.on_result('red sphere', False, 19.0, lift_height=0.25)    # after the lift: ignored
    rec = tracker.finish(20.0)
    assert rec.success and rec.failure == '' and rec.time_to_grasp_s == 18.0
    assert rec.lift_height == 0.25
    tracker.start(2, 'red sphere', 0, t=0.0)
    tracker.on_result('red sphere', False, 10.0, lift_height=0.157)
    rec = tracker.finish(30.0, 'no_grasp', 'the grasp attempt ended without a lift')
    assert not rec.success and rec.failure == 'dropped' and rec.grasped == 'red sphere'
    assert rec.reason == ('the red sphere was dropped after a lift to 0.157 m (success: above '
                          '0.22 m)')


def test_records_round_trip_csv_and_parquet(tmp_path) -> None:
    tracker = TrialTracker('set_locations', 'noise')
    records = [_trial(tracker, 2, 'red cube', 'red cube', 'red cube', True),
               _trial(tracker, 1, 'blue sphere', '', '', False)]
    csv_path, parquet_path = write_records(records, tmp_path)
    assert csv_path.read_text().splitlines()[0].split(',') == TrialRecord.columns()
    from_parquet = read_records(parquet_path)
    from_csv = read_records(csv_path)
    assert [r.trial for r in from_parquet] == [1, 2]          # trial order
    for a, b in zip(from_parquet, from_csv, strict=True):
        for name in TrialRecord.columns():
            va, vb = getattr(a, name), getattr(b, name)
            assert va == vb or (isinstance(va, float) and math.isnan(va) and math.isnan(vb)), name
    with pytest.raises(FileNotFoundError, match='give a run directory'):
        read_records(tmp_path / 'nowhere')


def test_summary_rates_and_wilson_intervals() -> None:
    low, high = wilson(57, 160)         # the paper's 35.6 % success on 160 trials
    assert math.isclose(low, 0.2866, abs_tol=1e-3) and math.isclose(high, 0.4328, abs_tol=1e-3)
    assert all(math.isnan(v) for v in wilson(0, 0))
    tracker = TrialTracker()
    records = [_trial(tracker, 1, 'red cube', 'red cube', 'red cube', True),
               _trial(tracker, 2, 'blue sphere', 'red cube', 'red cube', True),
               _trial(tracker, 3, 'blue sphere', '', '', False)]
    s = summarise(records)
    assert s['trials'] == 3 and s['success_count'] == 2
    assert math.isclose(s['correct_and_successful_rate'], 1 / 3)
    assert s['success_by_shape']['sphere']['trials'] == 2
    assert s['failures'] == {'no_grasp': 1}
    assert s['success_ci95'][0] < 2 / 3 < s['success_ci95'][1]


def test_protocol_draws_depend_on_seed_and_trial_only() -> None:
    targets = [set_locations_target(5, t, 9) for t in range(1, 200)]
    assert targets == [set_locations_target(5, t, 9) for t in range(1, 200)]
    assert set(targets) == set(range(9))
    assert targets != [set_locations_target(6, t, 9) for t in range(1, 200)]
    specs = [random_locations_trial(0, t) for t in range(1, 300)]
    assert {s.shape for s in specs} == {'cube', 'cylinder', 'sphere'}
    assert all(0.2 <= s.radius <= 0.7 and -170 <= s.angle_deg <= 170 for s in specs)
    assert random_locations_trial(0, 17) == specs[16]
    with pytest.raises(ValueError, match='no objects'):
        set_locations_target(0, 1, 0)


@pytest.mark.parametrize(('certainty', 'shown'), [(None, 'n/a'), (math.nan, 'n/a'), (0.0, '0.00'),
                                                  (0.166, '0.17')])
def test_report_shows_mean_certainty_or_n_a(certainty, shown) -> None:
    """No decoder (oracle, autonomous) gives n/a; a decoder that was never sure shows 0.00."""
    from mindgrasp_experiments.report import render_report

    text = render_report({'trials': 1, 'mean_certainty': certainty},
                         {'protocol': 'random_locations', 'subject': 'autonomous'})
    assert f'mean certainty {shown}.' in text
