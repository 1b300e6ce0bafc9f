"""The virtual subject on a fitted head (issue 27 section 5): ``--subject virtual:FILE.yaml`` is
calibrated on its head through the lock-step Graz session (real nodes in child processes, a
real bag), its decoder runs the experiment, the model is cached by content, and a bad file is
one line naming the fix."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from mindgrasp_classifier.model import MiModel
from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.experiment import Experiment
from mindgrasp_experiments.fitted_subject import fitted_model, load_fitted

HEAD = {'head_seed': 0, 'separability': 1.129, 'lateral_separability': 0.6796,
        'rest_separability': 0.938, 'nonstationarity': 1.3708}
REPO = Path(__file__).resolve().parents[2]


def _subject_file(folder: Path, head: dict | None = None, **extra) -> Path:
    path = folder / 'fitted.yaml'
    path.write_text(yaml.safe_dump({'virtual_amp': {'ros__parameters': head or HEAD}, **extra}),
                    encoding='utf-8')
    return path


@pytest.mark.slow
@pytest.mark.timeout(900)   # a short calibration session and two short trials on a loaded host
def test_the_fitted_subject_is_calibrated_on_its_head_and_runs_with_that_decoder(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('MINDGRASP_CACHE', str(tmp_path / 'cache'))
    path = _subject_file(tmp_path, calibration={'trials_per_class': 3, 'seed': 2})
    subject = f'virtual:{path}'
    fitted = load_fitted(subject)

    def run(name: str):
        return Experiment('set_locations', subject=subject, trials=1, seed=5, accuracy=1.0,
                          trial_timeout_s=30.0).run(tmp_path / name, log=lambda line: None)

    first = run('first')
    # the run's decoder is the one calibrated on this head with these settings
    model_param = yaml.safe_load((first.run_dir / 'params' / 'classifier.yaml').read_text())
    model_path = Path(next(iter(model_param.values()))['ros__parameters']['model'])
    assert model_path.parent == first.run_dir
    provenance = MiModel.load(model_path).provenance
    assert provenance['fitted_digest'] == fitted.digest()
    assert provenance['virtual_head'] == HEAD
    assert provenance['fitted_calibration']['trials_per_class'] == 3
    assert 0.0 <= provenance['heldout']['accuracy'] <= 1.0
    summary = json.loads((first.run_dir / 'summary.json').read_text())
    assert summary['run']['subject_args']['model'] == str(model_path)
    # the calibration session ran the fitted head through the real nodes, and so does the loop
    sessions = list((tmp_path / 'cache' / 'fitted_subjects' / 'sessions' / 'fitted').iterdir())
    assert len(sessions) == 1
    for params in (sessions[0] / '01_graz' / 'params' / 'virtual_amp.yaml',
                   sessions[0] / '02_heldout' / 'params' / 'virtual_amp.yaml',
                   first.run_dir / 'params' / 'virtual_amp.yaml'):
        values = next(iter(yaml.safe_load(params.read_text()).values()))['ros__parameters']
        assert {k: values[k] for k in HEAD} == HEAD, params
    assert (sessions[0] / '01_graz' / 'bag' / 'metadata.yaml').is_file()

    # a rerun takes the cached model (no second session) and gives the same records
    cached = fitted_model(fitted)
    stamp = cached.stat().st_mtime_ns
    second = run('second')
    assert cached.stat().st_mtime_ns == stamp
    assert len(list(sessions[0].parent.iterdir())) == 1
    assert (second.run_dir / 'records.csv').read_bytes() == \
        (first.run_dir / 'records.csv').read_bytes()
    assert (second.run_dir / model_path.name).read_bytes() == model_path.read_bytes()
    # calibrated again from scratch (another cache), the same seed gives the same decoder
    again = fitted_model(fitted, cache=tmp_path / 'cache2', log=lambda line: None)
    with np.load(again.with_suffix('.npz')) as a, np.load(cached.with_suffix('.npz')) as b:
        assert sorted(a.files) == sorted(b.files)
        assert all(np.array_equal(a[k], b[k]) for k in a.files)


@pytest.mark.parametrize(('content', 'message'), [
    (None, 'does not exist; write it with mindgrasp eeg fit-virtual'),
    ('virtual_amp: [1, 2', 'is not valid YAML'),
    ('other: 1\n', 'has no virtual_amp: ros__parameters'),
    ({'virtual_amp': {'ros__parameters': {'head_seed': 0}}},
     'lacks the fitted setting.*separability'),
    ({'virtual_amp': {'ros__parameters': {**HEAD, 'separability': 'high'}}},
     "separability: 'high', not a number"),
    ({'virtual_amp': {'ros__parameters': {**HEAD, 'lateral_separability': 3.0}}},
     'out of range.*lateral_separability'),
    ({'virtual_amp': {'ros__parameters': HEAD}, 'calibration': {'trials': 3}},
     'calibration.*trials_per_class'),
    ({'virtual_amp': {'ros__parameters': HEAD}, 'calibration': {'trials_per_class': 1}},
     'trials_per_class 1; give an integer >= 2'),
    ({'virtual_amp': {'ros__parameters': HEAD}, 'extra': 1}, 'unknown top-level key'),
])
def test_a_bad_fitted_subject_file_is_one_sentence_with_the_fix(tmp_path: Path, content,
                                                                message: str) -> None:
    path = tmp_path / 'head.yaml'
    if content is not None:
        path.write_text(content if isinstance(content, str) else yaml.safe_dump(content),
                        encoding='utf-8')
    with pytest.raises(ExperimentError, match=message) as info:
        load_fitted(f'virtual:{path}')
    assert '\n' not in str(info.value) and str(path) in str(info.value)


def test_the_digest_follows_the_head_and_the_calibration_settings(tmp_path: Path) -> None:
    base = load_fitted(f'virtual:{_subject_file(tmp_path)}').digest()
    (tmp_path / 'b').mkdir()
    other_head = load_fitted(f"virtual:{_subject_file(tmp_path / 'b', {**HEAD, 'head_seed': 1})}")
    (tmp_path / 'c').mkdir()
    other_cal = load_fitted(f"virtual:{_subject_file(tmp_path / 'c', calibration={'seed': 1})}")
    assert len({base, other_head.digest(), other_cal.digest()}) == 3
    # the defaults written out are the same subject as the defaults left out
    (tmp_path / 'd').mkdir()
    same = load_fitted(f"virtual:{_subject_file(tmp_path / 'd', calibration={'seed': 0})}")
    assert same.digest() == base


@pytest.mark.slow
def test_the_command_line_refuses_a_missing_fit_in_one_line(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'experiment', 'set-locations', '--trials',
         '1', '--subject', f'virtual:{tmp_path}/none.yaml', '--out', str(tmp_path / 'run')],
        capture_output=True, text=True, timeout=120, cwd=REPO)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and 'mindgrasp eeg fit-virtual' in lines[0], proc.stderr
    assert 'Traceback' not in proc.stderr and not (tmp_path / 'run' / 'records.csv').exists()


def test_the_shipped_fitted_subject_is_s001s_fit() -> None:
    fitted = load_fitted(f"virtual:{REPO / 'docs' / 'subjects' / 'eegmmidb_s001_virtual.yaml'}")
    assert fitted.head == HEAD        # src/mindgrasp_eeg/README.md: fit-virtual --seed 0
    assert fitted.calibration == {'trials_per_class': 20, 'seed': 0, 'accuracy': 1.0,
                                  'pipeline': 'mdm'}
