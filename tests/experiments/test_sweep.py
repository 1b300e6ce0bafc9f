"""``mindgrasp experiment sweep``: argument parsing and figures as plain functions, and one small
sweep end to end (the experiment profile's real nodes in lock-step, in a subprocess)."""

from __future__ import annotations

import csv
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.records import TrialRecord, TrialTracker, read_records
from mindgrasp_experiments.sweep import (
    combinations,
    parse_accuracies,
    parse_param,
    parse_seeds,
    parse_subjects,
    point_figures,
    point_name,
)

JSON_KEYS = ('accuracy', 'trials', 'interrupted_trials', 'success_rate',
             'correct_and_successful_rate', 'wrong_grasp_rate', 'wrong_grasp_ci95',
             'no_grasp_rate', 'median_time_to_correct_grasp_s', 'itr_bits_per_min',
             'online_accuracy', 'calibration_accuracy', 'mean_time_s')


def mindgrasp(*args: str, timeout: float = 1500.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=timeout,
                          env=dict(os.environ), check=False)


@pytest.mark.parametrize(('text', 'message'), [
    ('0,0.5', r'0 is outside \(0, 1\]'),
    ('0.5,1.2', r'1.2 is outside \(0, 1\]'),
    ('0.5,x', "'x' is not a number"),
    ('0.5,0.5', 'repeats an accuracy'),
])
def test_bad_accuracies_are_named(text: str, message: str) -> None:
    with pytest.raises(ExperimentError, match=message):
        parse_accuracies(text)


@pytest.mark.parametrize('text', ['fsm.certainty_threshold', 'certainty_threshold=0.3',
                                  'fsm.certainty_threshold=', 'fsm.x=0.3,,0.5'])
def test_bad_param_syntax_is_named(text: str) -> None:
    with pytest.raises(ExperimentError, match=r'give node\.parameter=v1,v2'):
        parse_param(text)


def test_combinations_and_point_names() -> None:
    params = [('fsm', 'certainty_threshold', [0.3, 0.5]), ('virtual_amp', 'decision_period',
                                                           [0.5])]
    combos = combinations(params)
    assert combos == [{'fsm.certainty_threshold': 0.3, 'virtual_amp.decision_period': 0.5},
                      {'fsm.certainty_threshold': 0.5, 'virtual_amp.decision_period': 0.5}]
    assert point_name(0.55, combos[0]) == \
        'acc0.55_fsm.certainty_threshold-0.3_virtual_amp.decision_period-0.5'
    assert combinations([]) == [{}]
    # subjects and seeds are point columns too; a subject file's path makes a flat name
    assert point_name(1.0, {'subject': 'docs/subjects/s 1.yaml', 'seed': 2}) == \
        'acc1_subject-docs_subjects_s_1.yaml_seed-2'
    assert point_name(1.0, {'subject': 'eegmmidb:1'}) == 'acc1_subject-eegmmidb_1'


def test_subjects_and_seeds_of_a_sweep() -> None:
    assert parse_subjects('virtual, eegmmidb:1,s.yaml') == ['virtual', 'eegmmidb:1', 's.yaml']
    assert parse_seeds('0,3, 7') == [0, 3, 7]
    with pytest.raises(ExperimentError, match='repeats a subject'):
        parse_subjects('virtual,virtual')
    with pytest.raises(ExperimentError, match='an empty entry'):
        parse_subjects('virtual,')
    with pytest.raises(ExperimentError, match="'-1' is not a whole number >= 0"):
        parse_seeds('0,-1')
    with pytest.raises(ExperimentError, match='repeats a seed'):
        parse_seeds('2,2')


def test_decisions_are_the_decoded_majority_over_a_held_intent() -> None:
    tracker = TrialTracker()
    tracker.start(trial=1, desired='red cube', t=0.0)
    tracker.on_intent('left_hand')
    for c in (0, 0, 1):                    # majority 0 = intent: a correct decision
        tracker.on_prediction(c, 0.5, t=1.0)
    tracker.on_intent('right_hand')
    for c in (0, 0, 1):                    # majority 0, intent 1: a wrong decision
        tracker.on_prediction(c, 0.5, t=2.0)
    rec = tracker.finish(t=3.0)
    assert (rec.decoder_windows, rec.decoder_hits) == (6, 3)
    assert (rec.decoder_decisions, rec.decoder_decision_hits) == (2, 1)


def test_point_figures_pool_windows_with_wilson_intervals() -> None:
    records = [TrialRecord(trial=1, success=True, correct_and_successful=True,
                           time_to_grasp_s=40.0, decoder_windows=10, decoder_hits=8,
                           decoder_decisions=2, decoder_decision_hits=2),
               TrialRecord(trial=2, success=True, time_to_grasp_s=60.0, decoder_windows=30,
                           decoder_hits=12, decoder_decisions=2, decoder_decision_hits=1)]
    p = point_figures(records, 0.7, {'fsm.certainty_threshold': 0.5})
    assert p['online_accuracy'] == pytest.approx(20 / 40)     # pooled, not a mean of trials
    assert p['online_decision_accuracy'] == pytest.approx(3 / 4)
    low, high = p['online_accuracy_ci95']
    assert low < 0.5 < high
    assert p['success_rate'] == 1.0 and p['correct_and_successful_rate'] == 0.5
    assert p['mean_time_s'] == pytest.approx(50.0)
    assert p['mean_time_ci95'][0] < 50.0 < p['mean_time_ci95'][1]
    assert p['fsm.certainty_threshold'] == 0.5


@pytest.mark.parametrize(('args', 'message'), [
    (['--accuracy', '0.3,1.5'], r'--accuracy: 1.5 is outside \(0, 1\]'),
    (['--param', 'fsm.certainty_threshold'], r'give node\.parameter=v1,v2'),
    (['--param', 'nope.x=1'], "no node 'nope' in this experiment"),
    (['--param', 'fsm.no_such_parameter=1'], "fsm has no parameter 'no_such_parameter'"),
    (['--param', 'fsm.certainty_threshold=high'], 'certainty_threshold takes a number'),
    (['--seeds', '1,x'], "--seeds: 'x' is not a whole number"),
    (['--subject', 'virtual,nobody'], "--subject: unknown subject 'nobody'"),
])
def test_bad_input_is_one_clear_line_and_exit_2(tmp_path: Path, args: list[str],
                                                message: str) -> None:
    result = mindgrasp('experiment', 'sweep', *args, '--out', str(tmp_path / 'bad'),
                       timeout=300)
    assert result.returncode == 2, result.stderr[-2000:]
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and 'Traceback' not in result.stderr, result.stderr
    assert re.search(message, lines[0]), lines[0]


@pytest.mark.timeout(2400)   # 4 whole trials through the real nodes, on a loaded machine
def test_a_small_sweep_writes_every_file_and_the_json(tmp_path: Path) -> None:
    """2 seeds x 2 accuracies x 2 trials (cut at 12 simulated s), with a swept parameter
    column: the paper's paradigm, whose subject imagines from the first second (in the scan
    paradigm it rests while the arm searches)."""
    out = tmp_path / 'sweep'
    result = mindgrasp('experiment', 'sweep', '--accuracy', '0.4,1.0', '--trials', '2',
                       '--seeds', '3,4', '--trial-timeout', '12', '--param',
                       'fsm.paradigm=paper', '--out', str(out), '--json',
                       '--no-progress')
    assert result.returncode == 0, result.stderr[-3000:]
    doc = json.loads(result.stdout.strip().splitlines()[-1])
    points = doc['points']
    assert [(p['seed'], p['accuracy']) for p in points] == [(3, 0.4), (3, 1.0), (4, 0.4),
                                                            (4, 1.0)]
    for p in points:
        assert all(k in p for k in JSON_KEYS), p
        assert p['trials'] == 2 and p['fsm.paradigm'] == 'paper'
        assert 0.0 <= p['success_rate'] <= 1.0
        assert p['online_windows'] > 0 and 0.0 <= p['online_accuracy'] <= 1.0
        point_dir = out / 'points' / p['point']
        for name in ('records.csv', 'records.parquet', 'summary.json', 'report.md'):
            assert (point_dir / name).is_file(), name
        records = read_records(point_dir)
        assert [r.trial for r in records] == [1, 2]
        assert {r.seed for r in records} == {p['seed']}
        assert sum(r.decoder_windows for r in records) == p['online_windows']
    # the decoder does better for the subject that always imagines the right class
    assert points[1]['online_accuracy'] > points[0]['online_accuracy']
    assert points[3]['online_accuracy'] > points[2]['online_accuracy']
    for name in ('sweep.csv', 'sweep.json', 'report.md', 'success_vs_accuracy.png',
                 'success_vs_accuracy.svg', 'time_vs_accuracy.png', 'time_vs_accuracy.svg',
                 'outcomes_vs_online_accuracy.png', 'outcomes_vs_online_accuracy.svg'):
        assert (out / name).stat().st_size > 0, name
    rows = list(csv.DictReader((out / 'sweep.csv').open(encoding='utf-8')))
    assert [(r['seed'], float(r['accuracy'])) for r in rows] == [('3', 0.4), ('3', 1.0),
                                                                  ('4', 0.4), ('4', 1.0)]
    assert all(r['fsm.paradigm'] == 'paper' for r in rows)
    assert json.loads((out / 'sweep.json').read_text())['points'] == points
    report = (out / 'report.md').read_text()
    assert '| accuracy | seed | fsm.paradigm |' in report
    assert 'success_vs_accuracy.png' in report
    assert all(math.isfinite(p['online_accuracy']) for p in points)


@pytest.mark.parametrize(('command', 'subject', 'message'), [
    ('set-locations', 'eegmmidb:x', 'write eegmmidb:<subject>'),
    ('sweep', 'eegmmidb:500', 'EEGMMIDB has subjects 1-109'),
    ('sweep', 'oracle', 'a sweep varies the accuracy of a pursuing subject'),
    ('set-locations', 'missing/subject.yaml', "The subject file '.*missing/subject.yaml' does not "
                                              'exist; give the path of a YAML subject file'),
    ('sweep', 'missing/subject.yml', 'subject.yml. does not exist; give the path'),
])
def test_bad_subject_is_one_clear_line_and_exit_2(tmp_path: Path, command: str, subject: str,
                                                  message: str) -> None:
    result = mindgrasp('experiment', command, '--subject', subject, '--trials', '1', '--out',
                       str(tmp_path / 'bad'), timeout=300)
    assert result.returncode == 2, result.stderr[-2000:]
    lines = [ln for ln in result.stderr.strip().splitlines() if not ln.startswith('Calibrating')]
    assert len(lines) == 1 and re.search(message, lines[0]), result.stderr


def test_applied_params_are_the_ones_in_the_run_directory(tmp_path: Path) -> None:
    """A point's params/<node>.yaml holds the values it ran with (issue 31, item 4)."""
    from mindgrasp_experiments.engine import lockstep_components
    from mindgrasp_experiments.sweep import apply_params
    from mindgrasp_launch import params as ros_params

    comps = lockstep_components('experiment', {'subject': 'virtual', 'protocol': 'set_locations',
                                               'seed': '0', 'trials': '1'}, tmp_path,
                                log=lambda *_: None)
    before = (tmp_path / 'vision.yaml').read_text()
    comps = apply_params(comps, {'fsm.paradigm': 'paper', 'fsm.confirm_threshold': 2.0},
                         tmp_path)
    fsm = ros_params.load_parameter_file(tmp_path / 'fsm.yaml')
    values = next(iter(fsm.values()))
    assert values['paradigm'] == 'paper' and values['confirm_threshold'] == 2.0
    assert (tmp_path / 'vision.yaml').read_text() == before      # untouched nodes stay as written
    fsm_comp = next(c for c in comps if c.label == 'fsm')
    assert fsm_comp.parameters['paradigm'] == 'paper'             # typed, never -p text
    assert fsm_comp.parameters['confirm_threshold'] == 2.0
    assert not any(a.startswith('paradigm:=') for a in fsm_comp.ros_args)


def test_experiment_params_stay_typed_to_the_node(monkeypatch) -> None:
    """Experiment.params reach the node typed (they went through text and back: a string that
    reads as a number became a double the node refused), and a typed value of the wrong kind is
    one clear line before any trial."""
    from mindgrasp_experiments.sweep import apply_params, check_params
    from mindgrasp_ros.graph.host import GraphRunner, Lockstep
    from mindgrasp_ros.graph.spec import NodeSpec

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / 'ros'))
    spec = NodeSpec('ticker', 'skeleton_node', parameters={'label': 'tick', 'rate': 20.0})
    typed = check_params([('ticker', 'label', ['0.5']), ('ticker', 'rate', [50])], [spec])
    assert typed == [('ticker', 'label', ['0.5']), ('ticker', 'rate', [50.0])]
    [spec] = apply_params([spec], {f'{node}.{name}': values[0] for node, name, values in typed})
    with GraphRunner(Lockstep()) as graph:
        node = graph.add(spec)
    assert node.params.label == '0.5' and node.params.rate == 50.0
    with pytest.raises(ExperimentError, match=r"--param ticker\.label=True: .* not a bool"):
        check_params([('ticker', 'label', [True])], [spec])
