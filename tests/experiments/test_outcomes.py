"""Outcomes that matter for an assistive arm: every trial is a correct grasp, a wrong grasp or no
grasp (cancels and wrong attempts without a lift included); the selection's information transfer
rate; one name per figure in the summary, the report, the sweep table and their JSON; interrupted
trials counted apart, outside every rate."""

from __future__ import annotations

import csv
import doctest
import json
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from mindgrasp_experiments import itr, records
from mindgrasp_experiments.itr import bits_per_selection, itr_bits_per_min
from mindgrasp_experiments.records import (
    OUTCOMES,
    TrialRecord,
    TrialTracker,
    outcome_of,
    read_records,
    write_records,
)
from mindgrasp_experiments.report import finite, render_report, write_run
from mindgrasp_experiments.summary import (
    calibration_accuracy_of,
    selection_choices,
    summarise,
    wilson,
)
from mindgrasp_experiments.sweep import point_figures, write_sweep

#: the hand-computed Wolpaw bits of a selection among 9 with P = 0.8:
#: log2 9 + 0.8 log2 0.8 + 0.2 log2(0.2 / 8) = 3.169925 - 0.257542 - 1.064386
BITS_9_08 = 1.847997


def _run(tracker: TrialTracker, states: list[tuple[int, str, str]], result: tuple | None = None,
         failure: str = '', desired: str = 'red cube') -> TrialRecord:
    """One trial: ``states`` as (state, object of interest, reason) from /fsm/state, then the
    grasp result (grasped, success) if any, then the end."""
    tracker.start(1, desired, 0, t=0.0, state=1, n_objects=9)
    for i, (state, ooi, reason) in enumerate(states):
        tracker.on_state(state, ooi, 1.0 + i, reason)
    if result is not None:
        tracker.on_result(result[0], result[1], 20.0, 0.25 if result[1] else 0.1)
    return tracker.finish(30.0, failure)


def test_a_lift_decides_the_outcome() -> None:
    tracker = TrialTracker()
    attempt = [(2, '', ''), (3, '', ''), (4, '', ''), (5, 'red cube', 'grasp')]
    assert _run(tracker, attempt, ('red cube', True)).outcome == 'correct_grasp'
    wrong = _run(tracker, attempt, ('blue cube', True))      # the vision named it red cube
    assert wrong.success and wrong.outcome == 'wrong_grasp'
    # a drop: the desired object slipped (no grasp); another object slipped (a wrong grasp)
    assert _run(tracker, attempt, ('red cube', False), 'no_grasp').outcome == 'no_grasp'
    dropped = _run(tracker, attempt, ('blue cube', False), 'no_grasp')
    assert dropped.failure == 'dropped' and dropped.outcome == 'wrong_grasp'


def test_a_grasp_closed_on_another_object_is_wrong_even_without_a_lift() -> None:
    tracker = TrialTracker()
    rec = _run(tracker, [(2, '', ''), (3, '', ''), (4, 'blue cube', ''), (5, 'blue cube', ''),
                         (6, 'blue cube', 'grasp failed: nothing in the gripper'), (1, '', '')],
               failure='no_grasp')
    assert not rec.success and rec.chosen == 'blue cube' and rec.outcome == 'wrong_grasp'
    # the same after a timeout or a stall: the attempt was made
    rec = _run(tracker, [(4, 'blue cube', ''), (5, 'blue cube', '')], failure='stalled')
    assert rec.outcome == 'wrong_grasp'
    # an approach to another object that never closed on it (no state 5) selected nothing
    rec = _run(tracker, [(2, 'blue cube', ''), (3, 'blue cube', ''), (4, 'blue cube', '')],
               failure='timeout')
    assert rec.chosen == '' and rec.outcome == 'no_grasp'


def test_a_cancel_is_no_grasp_and_the_trial_goes_on_until_a_later_attempt() -> None:
    tracker = TrialTracker()
    tracker.start(1, 'red cube', 0, t=0.0, state=1, n_objects=9)
    for i, (state, ooi, reason) in enumerate([
            (2, 'blue cube', 'selected'), (3, 'blue cube', ''), (4, 'blue cube', ''),
            (6, 'blue cube', 'cancelled by the user (both feet)'), (1, '', 'returned')]):
        tracker.on_state(state, ooi, float(i), reason)
    # 4-6-1 would end a failed attempt; a cancelled return does not end the trial
    assert not tracker.attempt_over
    rec = tracker.finish(120.0, 'timeout', 'no grasp within 120 s')
    assert rec.states == '1-2-3-4-6-1' and rec.cancels == 1
    assert rec.chosen == '' and rec.outcome == 'no_grasp'
    # cancelled, then a later attempt lifts the desired object
    rec = _run(tracker, [(2, 'blue cube', ''), (6, '', 'cancelled'), (1, '', ''),
                         (2, 'red cube', ''), (4, 'red cube', ''), (5, 'red cube', '')],
               ('red cube', True))
    assert rec.cancels == 1 and rec.outcome == 'correct_grasp'
    # the cancel announced while the joints are locked (the state is still 4), then the return
    tracker.start(2, 'red cube', 0, t=0.0, state=1)
    tracker.on_state(4, 'blue cube', 1.0, 'aligned')
    tracker.on_state(4, 'blue cube', 1.1, 'locked: cancelled by the user')
    tracker.on_state(6, 'blue cube', 1.5, 'returning')
    tracker.on_state(1, '', 9.0, 'at start')
    assert not tracker.attempt_over
    assert tracker.finish(10.0, 'stalled').cancels == 1
    # without a cancel, a return after the final approach ends the attempt
    tracker.start(3, 'red cube', 0, t=0.0, state=1)
    for i, state in enumerate((2, 3, 4, 6, 1)):
        tracker.on_state(state, 'blue cube', float(i), 'final approach aborted: lost it')
    assert tracker.attempt_over
    assert tracker.finish(10.0, 'no_grasp').cancels == 0


def test_interrupted_trials_are_no_grasp_and_outside_every_rate() -> None:
    interrupted = TrialRecord(2, desired='red cube', chosen='blue cube', failure='interrupted',
                              duration_s=5.0)
    assert outcome_of(interrupted) == 'no_grasp' and interrupted.outcome == 'no_grasp'
    done = TrialRecord(1, desired='red cube', grasped='red cube', success=True,
                       correct_and_successful=True, time_to_grasp_s=12.0, duration_s=15.0)
    s = summarise([done, interrupted])
    assert s['trials'] == 1 and s['interrupted_trials'] == 1
    assert s['success_rate'] == 1.0 and s['no_grasp_rate'] == 0.0
    assert s['failures'] == {} and s['mean_duration_s'] == 15.0
    # the trial manager's end-of-run tally: "1 trials (1 interrupted, not counted): correct
    # grasp 100.0 %", not "2 trials: grasp success 50.0 %"
    from mindgrasp_experiments.trial_manager_node import TrialManagerNode

    logged: list[str] = []
    node = SimpleNamespace(records=[done, interrupted],
                           get_logger=lambda: SimpleNamespace(info=logged.append))
    TrialManagerNode._report(node)
    assert logged[0].startswith('1 trials (1 interrupted, not counted): correct grasp 100.0 %')
    assert 'grasp success 100.0 %' in logged[0]


def test_every_record_has_one_of_three_outcomes_and_old_files_are_read(tmp_path: Path) -> None:
    assert OUTCOMES == ('correct_grasp', 'wrong_grasp', 'no_grasp')
    assert TrialRecord(1).outcome == 'no_grasp'           # e.g. a trial that failed to build
    with pytest.raises(ValueError, match="Unknown trial outcome 'lost'"):
        TrialRecord(1, outcome='lost')
    # an older records.csv: decoder_accuracy (now online_accuracy), no outcome, no n_objects
    old = tmp_path / 'records.csv'
    columns = ['trial', 'desired', 'chosen', 'grasped', 'success', 'correct_and_successful',
               'decoder_accuracy', 'failure']
    with old.open('w', newline='', encoding='utf-8') as f:
        writer = csv.writer(f, lineterminator='\n')
        writer.writerow(columns)
        writer.writerow([1, 'red cube', 'red cube', 'red cube', True, True, '0.75', ''])
        writer.writerow([2, 'red cube', 'blue cube', '', False, False, '', 'no_grasp'])
    first, second = read_records(old)
    assert first.online_accuracy == 0.75 and first.outcome == 'correct_grasp'
    assert math.isnan(second.online_accuracy) and second.outcome == 'wrong_grasp'
    # and the new columns round-trip
    write_records([first, second], tmp_path / 'new')
    header = (tmp_path / 'new' / 'records.csv').read_text().splitlines()[0].split(',')
    assert {'outcome', 'online_accuracy', 'n_objects', 'cancels'} <= set(header)
    assert 'decoder_accuracy' not in header
    assert [r.outcome for r in read_records(tmp_path / 'new')] == ['correct_grasp',
                                                                   'wrong_grasp']


@pytest.mark.parametrize(('names', 'judged', 'hits'), [
    ((), 2, 1),                       # no class names: the four imagery classes, as before
    (('left_hand', 'right_hand', 'both_hands', 'both_feet'), 2, 1),
    (('left_hand', 'right_hand', 'both_hands', 'both_feet', 'rest'), 4, 2),
])
def test_rest_windows_count_when_the_model_knows_rest(names: tuple, judged: int,
                                                      hits: int) -> None:
    tracker = TrialTracker()
    tracker.start(1, 'red cube', t=0.0)
    tracker.on_intent('left_hand')
    tracker.on_prediction(0, 0.5, 1.0, names)       # a hit
    tracker.on_prediction(1, 0.5, 1.1, names)       # a miss
    tracker.on_intent('rest')
    tracker.on_prediction(4, 0.5, 2.0, names)       # rest decoded as rest
    tracker.on_intent('')                           # an empty intent is rest too
    tracker.on_prediction(2, 0.5, 3.0, names)       # rest decoded as both hands
    tracker.on_intent('daydreaming')                # not a class: never judged
    tracker.on_prediction(2, 0.5, 4.0, names)
    rec = tracker.finish(5.0)
    assert (rec.decoder_windows, rec.decoder_hits) == (judged, hits)
    assert rec.online_accuracy == pytest.approx(hits / judged)
    assert rec.n_predictions == 5


def test_itr_against_hand_computed_values() -> None:
    assert bits_per_selection(9, 0.8) == pytest.approx(BITS_9_08, abs=1e-6)
    assert bits_per_selection(4, 0.5) == pytest.approx(2 - 0.5 - 0.5 * math.log2(6), abs=1e-12)
    assert bits_per_selection(9, 1.0) == pytest.approx(math.log2(9))
    assert bits_per_selection(2, 1.0) == 1.0
    for p in (0.0, 0.05, 1 / 9):                    # at or below chance: nothing transferred
        assert bits_per_selection(9, p) == 0.0
    assert math.isnan(bits_per_selection(9, math.nan))
    # 10 selections in 5 minutes at P = 0.8 among 9: 1.848 * 10 / 5
    assert itr_bits_per_min(9, 0.8, 10, 5.0) == pytest.approx(2 * BITS_9_08, abs=1e-5)
    assert itr_bits_per_min(9, math.nan, 0, 5.0) == 0.0
    assert math.isnan(itr_bits_per_min(9, 1.0, 3, 0.0))
    with pytest.raises(ValueError, match='at least 2 choices'):
        bits_per_selection(1, 1.0)
    with pytest.raises(ValueError, match=r'within 0\.\.1'):
        bits_per_selection(9, 1.5)
    for module in (itr, records):
        assert doctest.testmod(module).failed == 0, module.__name__


def _set_location_records() -> list[TrialRecord]:
    """4 correct grasps (10-40 s), 1 wrong lift, 1 nothing, 1 interrupted; 30 s per trial."""
    out = [TrialRecord(t, protocol='set_locations', desired='red cube', grasped='red cube',
                       n_objects=9, success=True, correct_and_successful=True,
                       time_to_grasp_s=10.0 * t, duration_s=30.0, decoder_windows=10,
                       decoder_hits=t + 4, decoder_decisions=2, decoder_decision_hits=1)
           for t in (1, 2, 3, 4)]
    out.append(TrialRecord(5, protocol='set_locations', desired='red cube', n_objects=9,
                           grasped='blue cube', success=True, time_to_grasp_s=5.0,
                           duration_s=30.0))
    out.append(TrialRecord(6, protocol='set_locations', desired='red cube', n_objects=9,
                           failure='timeout', duration_s=30.0))
    out.append(TrialRecord(7, protocol='set_locations', desired='red cube', n_objects=9,
                           grasped='blue cube', success=True, failure='interrupted',
                           duration_s=99.0, decoder_windows=50))
    return out


def test_summary_names_the_outcomes_itr_and_decoder_once() -> None:
    recs = _set_location_records()
    s = summarise(recs, calibration_accuracy=0.925)
    assert s['trials'] == 6 and s['interrupted_trials'] == 1
    assert s['correct_and_successful_rate'] == pytest.approx(4 / 6)
    assert (s['wrong_grasp_count'], s['no_grasp_count']) == (1, 1)
    assert s['wrong_grasp_rate'] == pytest.approx(1 / 6)
    assert s['wrong_grasp_ci95'] == pytest.approx(list(wilson(1, 6)))
    assert s['no_grasp_ci95'] == pytest.approx(list(wilson(1, 6)))
    assert s['median_time_to_correct_grasp_s'] == 25.0       # the wrong lift (5 s) left out
    # ITR: N = 9, P = 4/5, 5 selections in 6 trials x 30 s = 3 min
    assert (s['itr_choices'], s['selections']) == (9, 5)
    assert s['selection_accuracy'] == pytest.approx(0.8)
    assert s['itr_bits_per_min'] == pytest.approx(BITS_9_08 * 5 / 3, abs=1e-5)
    # the decoder: pooled over windows of the counted trials (5+6+7+8 of 40)
    assert s['online_accuracy'] == pytest.approx(26 / 40) and s['online_windows'] == 40
    assert s['online_decision_accuracy'] == 0.5 and s['calibration_accuracy'] == 0.925
    assert 'decoder_accuracy' not in s and 'correct_and_success_rate' not in s
    assert math.isnan(summarise(recs)['calibration_accuracy'])
    # no correct grasp: no median time, no information; strict JSON says null
    none = summarise(recs[5:6])
    assert math.isnan(none['median_time_to_correct_grasp_s']) and none['itr_bits_per_min'] == 0
    assert json.loads(json.dumps(finite(none)))['median_time_to_correct_grasp_s'] is None


def test_selection_choices() -> None:
    assert selection_choices([TrialRecord(1, n_objects=9)] * 3) == 9
    # random locations: one object in the scene, at least 2
    assert selection_choices([TrialRecord(1, protocol='random_locations', n_objects=1)]) == 2
    # records from before n_objects: set locations has 9
    assert selection_choices([TrialRecord(1, protocol='set_locations')]) == 9
    assert selection_choices([]) == 0


def test_the_run_directory_shows_outcomes_and_calibration(tmp_path: Path) -> None:
    """summary.json, report.md and the set-location map of a run; the calibration accuracy is
    read from the model the run's classifier parameters name."""
    model = tmp_path / 'model.json'
    model.write_text(json.dumps({'provenance': {'cross_validation': {
        'balanced_accuracy': 0.875}}}), encoding='utf-8')
    params = tmp_path / 'run' / 'params'
    params.mkdir(parents=True)
    (params / 'classifier.yaml').write_text(
        f'/**:\n  ros__parameters:\n    model: {model}\n', encoding='utf-8')
    assert calibration_accuracy_of(tmp_path / 'run') == 0.875
    assert calibration_accuracy_of(tmp_path / 'nowhere') is None
    recs = _set_location_records()
    recs[4].desired_x, recs[4].desired_y = 0.5, 0.0
    doc = write_run(tmp_path / 'run', recs, {'protocol': 'set_locations', 'subject': 'virtual'})
    saved = json.loads((tmp_path / 'run' / 'summary.json').read_text())['summary']
    assert saved['calibration_accuracy'] == 0.875 == doc['summary']['calibration_accuracy']
    for key in ('wrong_grasp_rate', 'wrong_grasp_ci95', 'no_grasp_rate',
                'correct_and_successful_rate', 'median_time_to_correct_grasp_s',
                'itr_bits_per_min', 'online_accuracy', 'interrupted_trials'):
        assert key in saved, key
    report = (tmp_path / 'run' / 'report.md').read_text()
    assert 'outcome **correct grasp**' in report and '66.7 % (4/6)' in report
    assert 'outcome **wrong grasp**' in report and '16.7 % (1/6)' in report
    assert 'outcome **no grasp**' in report
    assert 'median time to a correct grasp | 25.0 s' in report
    assert f'{BITS_9_08 * 5 / 3:.2f} bits/min' in report
    assert 'decoder online accuracy' in report and '65.0 % of 40 windows' in report
    assert 'decoder calibration accuracy (the model\'s cross-validation) | 87.5 %' in report
    assert '1 interrupted trial(s) (Ctrl-C) are left out of every figure.' in report
    assert (tmp_path / 'run' / 'set_location_map.svg').stat().st_size > 0
    svg = (tmp_path / 'run' / 'set_location_map.svg').read_text()
    assert 'wrong grasp (1)' in svg and 'correct grasp (4)' in svg and 'no grasp (1)' in svg
    # a given calibration accuracy wins over the parameters
    text = render_report(summarise(recs, 0.5), {'protocol': 'set_locations'})
    assert '| 50.0 % |' in text


def test_sweep_rows_carry_the_summary_names(tmp_path: Path) -> None:
    recs = _set_location_records()
    row = point_figures(recs, 0.8, {'fsm.certainty_threshold': 0.5}, calibration_accuracy=0.9)
    s = summarise(recs, 0.9)
    for key in ('correct_and_successful_rate', 'wrong_grasp_rate', 'wrong_grasp_ci95',
                'no_grasp_rate', 'median_time_to_correct_grasp_s', 'itr_bits_per_min',
                'online_accuracy', 'online_accuracy_ci95', 'calibration_accuracy',
                'interrupted_trials'):
        assert row[key] == s[key], key
    assert 'correct_and_success_rate' not in row and row['trials'] == 6
    assert row['mean_time_s'] == pytest.approx((10 + 20 + 30 + 40 + 5) / 5)
    doc = write_sweep(tmp_path, [{'point': 'acc0.8', **row}], ['fsm.certainty_threshold'],
                      {'seed': 0, 'trials': 7})
    (point,) = json.loads((tmp_path / 'sweep.json').read_text())['points']
    assert point == doc['points'][0] and point['calibration_accuracy'] == 0.9
    (line,) = list(csv.DictReader((tmp_path / 'sweep.csv').open(encoding='utf-8')))
    for key in ('wrong_grasp_rate', 'wrong_grasp_ci95_low', 'correct_and_successful_rate',
                'median_time_to_correct_grasp_s', 'itr_bits_per_min', 'calibration_accuracy'):
        assert line[key] != '', key
    report = (tmp_path / 'report.md').read_text()
    assert '| wrong grasp | no grasp |' in report and 'calibration accuracy |' in report
    assert '| 90.0 % |' in report and '1 interrupted trial(s)' in report
