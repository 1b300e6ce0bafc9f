"""The experiment as an object (issue 29): configuration in, results out, as the CLI prints."""

from __future__ import annotations

import json

import pytest

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.experiment import Experiment

pytestmark = pytest.mark.slow


def test_an_experiment_runs_from_python_and_writes_the_run_directory(tmp_path) -> None:
    experiment = Experiment('set_locations', subject='oracle', trials=1, seed=3,
                            params={'fsm.paradigm': 'scan'}, trial_timeout_s=200.0)
    results = experiment.run(tmp_path / 'run', log=lambda line: None)
    assert [r.trial for r in results.records] == [1]
    assert results.records[0].outcome in ('correct_grasp', 'wrong_grasp', 'no_grasp')
    assert not results.interrupted and not results.unwritten
    summary = json.loads((tmp_path / 'run' / 'summary.json').read_text())
    assert summary['summary']['trials'] == 1
    assert summary['run']['params'] == {'fsm.paradigm': 'scan'}
    figures = results.figures()
    assert figures['run_dir'] == str(tmp_path / 'run')
    assert figures['correct_and_successful_rate'] == summary['summary'][
        'correct_and_successful_rate']
    assert figures['sim_s'] > 0 and figures['real_time_factor'] > 0
    assert 'paradigm: scan' in (tmp_path / 'run' / 'params' / 'fsm.yaml').read_text()


@pytest.mark.parametrize(('params', 'message'), [
    ({'nosuch.gain': 1}, "no node 'nosuch'"),
    ({'fsm.no_such_parameter': 1}, "fsm has no parameter 'no_such_parameter'"),
    ({'fsm.paradigm': 'telepathy'}, 'paradigm'),
])
def test_a_bad_parameter_is_refused_before_any_trial(tmp_path, params, message) -> None:
    with pytest.raises(ExperimentError, match=message):
        Experiment('set_locations', subject='oracle', trials=1, params=params).run(
            tmp_path / 'run', log=lambda line: None)
    assert not (tmp_path / 'run' / 'records.csv').exists()
