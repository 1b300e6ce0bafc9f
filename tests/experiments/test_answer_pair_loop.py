"""The controller answering with left_right in a lock-step run of the experiment's real nodes:
the oracle subject reads the pair from /fsm/state and imagines left hand for yes and right hand
for no; the record, summary and report name the pair."""

from __future__ import annotations

import json

import pytest

from mindgrasp_experiments.experiment import Experiment

pytestmark = pytest.mark.slow


def test_the_loop_answers_with_left_right(tmp_path) -> None:
    experiment = Experiment('set_locations', subject='oracle', trials=1, seed=3,
                            params={'fsm.answer_pair': 'left_right'}, trial_timeout_s=300.0)
    results = experiment.run(tmp_path / 'run', log=lambda line: None)
    record = results.records[0]
    assert record.answer_pair == 'left_right'
    assert record.outcome == 'correct_grasp', record
    summary = json.loads((tmp_path / 'run' / 'summary.json').read_text())['summary']
    assert summary['answer_pair'] == 'left_right'
    assert 'answer_pair' in (tmp_path / 'run' / 'records.csv').read_text().splitlines()[0]
    report = (tmp_path / 'run' / 'report.md').read_text()
    assert 'Answer pair **left_right** (yes: imagine the left hand; no: imagine the right ' \
           'hand)' in report
