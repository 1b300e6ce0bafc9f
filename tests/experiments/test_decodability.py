"""Decodability of the virtual subject: the settings of SyntheticEEG (separability,
lateral_separability, rest_separability, nonstationarity), the figures of
mindgrasp_experiments.decodability, and ``mindgrasp eeg fit-virtual`` against real EEGMMIDB S001
(MNE_DATASETS_EEGBCI_PATH, ../shared/data)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from mindgrasp_common.mi import REST
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import NAUTILUS_32
from mindgrasp_eeg.synthetic import RunConditions, SyntheticEEG
from mindgrasp_experiments import decodability as dec

FS = 250.0
#: the original subject, spelled out
DEFAULTS = dict(separability=1.0, lateral_separability=1.0, rest_separability=0.0,
                nonstationarity=0.0)
#: a session with rest and every class, class changes without rest between them, odd chunks
SCRIPT = [(None, 317), (0, 500), (1, 250), (None, 123), (2, 611), (3, 400), (None, 77), (3, 90)]


def play(gen: SyntheticEEG, script: list[tuple[int | None, int]] = SCRIPT) -> np.ndarray:
    return np.vstack([gen.generate(n, cls) for cls, n in script])


@pytest.mark.parametrize('kwargs', [dict(seed=3), dict(seed=7, head_seed=2, erd_depth=0.8,
                                                      blink_rate=0.5, emg_rate=0.3,
                                                      line_noise=1e-6)])
def test_defaults_reproduce_the_original_output_exactly(kwargs: dict) -> None:
    omitted = play(SyntheticEEG(**kwargs))
    explicit = play(SyntheticEEG(**kwargs, **DEFAULTS))
    assert np.array_equal(omitted, explicit)               # bit for bit, not approximately
    gen = SyntheticEEG(**kwargs)
    assert gen.run is None                                  # nothing drawn for the run
    depth = kwargs.get('erd_depth', 0.5)
    # the original ERD: 1 - erd_depth on the class's motor areas, nothing anywhere else
    assert gen.erd_target(0).tolist() == [1.0, 1.0, 1.0 - depth, 1.0, 1.0, 1.0 - depth, 1.0]
    assert gen.erd_target(2).tolist() == [1.0, 1 - depth, 1 - depth, 1.0, 1 - depth, 1 - depth,
                                          1.0]
    assert gen.erd_target(None).tolist() == [1.0] * 7


def test_settings_shape_the_erd_as_documented() -> None:
    gen = SyntheticEEG(separability=0.6, lateral_separability=0.5, rest_separability=0.4)
    # left hand: contralateral (right motor) (1 + 0.5) / 2, ipsilateral (1 - 0.5) / 2 of 0.3
    assert gen.erd_depths(0) == pytest.approx({'right_motor': 0.225, 'left_motor': 0.075,
                                               'occipital': 0.2})
    assert gen.erd_depths(2) == pytest.approx({'left_motor': 0.3, 'right_motor': 0.3,
                                               'occipital': 0.2})
    assert gen.erd_depths(3) == pytest.approx({'vertex': 0.3, 'occipital': 0.2})
    assert gen.erd_depths(None) == {}
    assert SyntheticEEG(separability=3.0).erd_depths(1) == {'left_motor': 1.0}   # capped


def test_nonstationarity_changes_a_second_runs_statistics() -> None:
    def log_power(seed: int, ns: float) -> np.ndarray:
        x = SyntheticEEG(seed=seed, nonstationarity=ns).generate(int(60 * FS), None)
        return np.log(x.var(axis=0))

    # stationary: two runs differ by estimation noise only; non-stationary: by far more
    assert np.abs(log_power(1, 0.0) - log_power(2, 0.0)).max() < 0.25
    assert np.abs(log_power(1, 1.0) - log_power(2, 1.0)).max() > 0.5
    # the same run seed gives the same conditions, scaled by the setting
    a, b = (SyntheticEEG(seed=4, nonstationarity=ns).run for ns in (0.5, 1.0))
    assert a is not None and b is not None
    np.testing.assert_allclose(2 * a.cap_shift_mm, b.cap_shift_mm)
    assert not np.array_equal(SyntheticEEG(seed=4).head.mixing,
                              SyntheticEEG(seed=4, nonstationarity=1.0).head.mixing)


def test_nonstationary_output_is_seeded_and_chunking_free() -> None:
    whole = play(SyntheticEEG(seed=9, nonstationarity=1.5))
    again = play(SyntheticEEG(seed=9, nonstationarity=1.5))
    assert np.array_equal(whole, again)
    split = [(cls, part) for cls, n in SCRIPT for part in (n // 3, n - n // 3)]
    np.testing.assert_allclose(play(SyntheticEEG(seed=9, nonstationarity=1.5), split), whole,
                               rtol=0, atol=1e-18)
    z = np.linspace(-1, 1, RunConditions.N_DRAWS)
    given = SyntheticEEG(seed=9, nonstationarity=1.0, run_normals=z).run
    expected = RunConditions.from_normals(1.0, z)
    assert given is not None
    np.testing.assert_array_equal(given.source_gain, expected.source_gain)
    np.testing.assert_array_equal(given.cap_shift_mm, expected.cap_shift_mm)


@pytest.mark.parametrize(('kwargs', 'message'), [
    (dict(separability=-0.1), 'separability must be >= 0'),
    (dict(lateral_separability=1.5), 'lateral_separability must be within 0..1'),
    (dict(rest_separability=-1.0), 'rest_separability must be >= 0'),
    (dict(nonstationarity=float('nan')), 'nonstationarity must be >= 0'),
    (dict(nonstationarity=1.0, run_normals=np.zeros(3)), 'run_normals must have shape'),
])
def test_bad_settings_are_named(kwargs: dict, message: str) -> None:
    with pytest.raises(EEGError, match=message):
        SyntheticEEG(**kwargs)


@pytest.fixture(scope='module')
def protocol() -> tuple[list[dec.RunSchedule], list[dec.RunSchedule]]:
    return dec.eegmmidb_like_schedules(seed=0)


def test_separability_zero_is_chance_and_more_separability_decodes_better(protocol) -> None:
    cal, test = protocol
    scores = {s: dec.synthetic_figures(cal, test, separability=s, repeats=4).scores()
              for s in (0.0, 0.4, 1.0)}
    assert abs(scores[0.0]['four_class'] - 0.25) < 0.12         # chance: 4 classes
    for name in ('left_right', 'hands_feet', 'rest_both_hands'):
        assert abs(scores[0.0][name] - 0.5) < 0.15, name
    assert scores[0.0]['four_class'] < scores[0.4]['four_class'] < scores[1.0]['four_class']
    assert scores[1.0]['four_class'] > 0.8 and scores[1.0]['hands_feet'] > 0.9


def test_lateral_and_rest_separability_act_on_their_figures(protocol) -> None:
    cal, test = protocol
    lateral = dec.synthetic_figures(cal, test, lateral_separability=0.0, repeats=2).scores()
    assert abs(lateral['left_right'] - 0.5) < 0.15 < lateral['hands_feet'] - 0.5
    rest = dec.synthetic_figures(cal, test, separability=0.0, rest_separability=1.0,
                                 repeats=2).scores()
    assert rest['rest_imagery'] > 0.8 and abs(rest['four_class'] - 0.25) < 0.15


def test_the_same_seed_gives_the_same_figures(protocol) -> None:
    cal, test = protocol
    a, b = (dec.synthetic_figures(cal, test, separability=0.5, nonstationarity=1.0, repeats=2,
                                  seed=5) for _ in range(2))
    assert a.accuracy == b.accuracy
    assert a.repeats == 2 and a.n_test['four_class'] == [8, 7, 8, 7]


def test_measure_labels_rest_and_needs_both_sets(protocol) -> None:
    cal, _test = protocol
    runs = dec.synthetic_runs(cal, seed=1)
    assert {int(c) for c in runs[0].events[:, 1]} == {0, 1, REST}
    assert runs[0].channels == list(NAUTILUS_32) and runs[0].rate == FS
    with pytest.raises(EEGError, match='calibration and test'):
        dec.measure(runs, [])
    # a subject without feet trials: the figures that need them are not measurable
    only_lr = dec.measure(runs[:1], dec.synthetic_runs(cal[:1], seed=2))
    assert np.isnan(only_lr.score('hands_feet')) and np.isfinite(only_lr.score('left_right'))


def test_figures_use_the_classifier_pipelines() -> None:
    from mindgrasp_classifier.evaluation import TASKS
    from mindgrasp_classifier.pipelines import MdmClassifier, TsLrClassifier

    mdm, ts_lr = (dec.make_pipeline(name) for name in dec.PIPELINES)
    assert type(mdm) is MdmClassifier and mdm.metric == 'logeuclid'
    assert type(ts_lr) is TsLrClassifier and ts_lr.metric == 'logeuclid'
    assert ts_lr.class_weight == 'balanced' and ts_lr.C == 1.0
    assert dec.FIGURES is TASKS                   # the tasks of mindgrasp evaluate decoding
    with pytest.raises(EEGError, match="Unknown decodability pipeline 'lda'"):
        dec.make_pipeline('lda')


def test_real_subject_figures_are_above_chance() -> None:
    real = dec.replay_figures('eegmmidb:1')
    assert real.n_test['four_class'] == [8, 7, 7, 8] and real.n_test['rest_imagery'] == [30, 30]
    for fig in dec.FIGURES:
        assert real.score(fig.name) > fig.chance + 0.15, fig.name
        assert 0.03 < real.standard_error(fig.name) < 0.15


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'eeg', 'fit-virtual',
                           *args], capture_output=True, text=True, timeout=600)


def test_fit_virtual_names_a_bad_subject_in_one_line() -> None:
    proc = run_cli('--subject', 'eegmmidb:0')
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "mindgrasp eeg fit-virtual: 'eegmmidb:0': EEGMMIDB has subjects 1-109; write e.g. "
        'eegmmidb:1.']


@pytest.mark.slow
def test_fit_virtual_runs_end_to_end_on_a_small_budget(tmp_path: Path) -> None:
    out = tmp_path / 'virtual.yaml'
    proc = run_cli('--subject', 'eegmmidb:1', '--repeats', '2', '--iterations', '1',
                   '--jobs', '2', '--seed', '3', '--output', str(out), '--json')
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(proc.stdout)
    assert set(doc['params']) == set(dec.PARAMETER_BOUNDS)
    assert doc['n_evaluations'] <= 8 and doc['synthetic']['repeats'] == 2
    assert doc['check']['repeats'] == 4                      # fresh sessions: twice as many
    assert doc['real']['score']['hands_feet'] == pytest.approx(0.866, abs=0.01)
    params = yaml.safe_load(out.read_text())['virtual_amp']['ros__parameters']
    assert params.pop('head_seed') == 0                      # the head the values are for
    assert params == pytest.approx(doc['params'])
    for key, (lo, hi) in dec.PARAMETER_BOUNDS.items():
        assert lo <= params[key] <= hi
    table = run_cli('--subject', 'eegmmidb:1', '--repeats', '1', '--iterations', '1')
    assert table.returncode == 0, table.stderr
    assert 'rest vs both hands' in table.stdout and 'fitted: separability' in table.stdout
