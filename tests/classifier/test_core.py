"""Decoder core: filter, windows, pipelines, certainty, online/offline agreement, model files."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from pyriemann.classification import MDM, FgMDM
from pyriemann.datasets import make_matrices
from scipy import signal

from mindgrasp_classifier.decoder import (
    AdaptationConfig,
    MiDecoder,
    Prediction,
    Rejected,
    decode_windows,
    filter_recording,
    window_covariances,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.pipelines import PIPELINES, MdmClassifier, certainty, make_classifier
from mindgrasp_classifier.preprocessing import (
    CausalBandpass,
    design_bandpass,
    select_channels,
    window_ends,
)
from mindgrasp_classifier.training import (
    TrainingConfig,
    evaluate,
    score_predictions,
    stream_recording,
    train,
)

from .classifier_synth import CHANNELS, RATE, make_recording


@pytest.fixture(scope='module')
def session():
    return make_recording(trials_per_class=8, seed=0)


@pytest.fixture(scope='module')
def trained(session):
    return train([session], TrainingConfig(channels='all', cv_folds=3))


def test_chunked_filter_equals_offline():
    rng = np.random.RandomState(1234)
    x = rng.randn(2000, 5) * 1e-5 + 3e-5
    sos = design_bandpass(8, 30, 250.0)
    whole = CausalBandpass(sos, 5).process(x)
    zi = signal.sosfilt_zi(sos)[:, :, None] * x[0][None, None, :]
    np.testing.assert_allclose(whole, signal.sosfilt(sos, x, axis=0, zi=zi)[0], atol=1e-12)
    filt = CausalBandpass(sos, 5)
    sizes = rng.randint(1, 40, size=200)
    bounds = np.concatenate([[0], np.cumsum(sizes)])
    parts = [filt.process(x[a:b]) for a, b in itertools.pairwise(bounds)
             if a < len(x)]
    chunked = np.concatenate(parts)[:len(x)]
    assert np.max(np.abs(chunked - whole)) < 1e-6 * np.max(np.abs(whole))
    np.testing.assert_allclose(chunked, whole, atol=1e-6)


def test_bandpass_rejects_bad_edges():
    with pytest.raises(ClassifierError, match='does not fit a sampling rate of 50'):
        design_bandpass(8, 30, 50.0)


def test_window_grid():
    ends = window_ends(0, 100, 32, 8)
    assert ends[0] == 31 and np.all(np.diff(ends) == 8) and np.all((ends + 1) % 8 == 0)
    assert len(window_ends(0, 20, 32, 8)) == 0


def test_channel_selection():
    assert select_channels(['Fp1', 'C3', 'cz', 'C4', 'O1'], 'motor') == ['C3', 'cz', 'C4']
    assert select_channels(['A', 'B'], 'all') == ['A', 'B']
    assert select_channels(['Fp1', 'C3', 'Cz'], ['cz', 'c3']) == ['Cz', 'C3']
    with pytest.raises(ClassifierError, match=r"channels \['C5'\] are not in the recording"):
        select_channels(['C3', 'Cz'], ['C5'])
    with pytest.raises(ClassifierError, match='Only 1 motor-strip channels'):
        select_channels(['Fp1', 'Cz', 'O1'], 'motor')


@pytest.mark.parametrize('name', PIPELINES)
def test_pipelines_separate_known_class_covariances(name):
    rng = np.random.RandomState(1234)
    means = make_matrices(4, 6, 'spd', rng)
    covs, labels = [], []
    for k, m in enumerate(means):
        root = np.linalg.cholesky(m)
        for _ in range(40):
            x = root @ rng.randn(6, 200)
            covs.append(x @ x.T / 200)
            labels.append(k)
    covs, labels = np.array(covs), np.array(labels)
    clf = make_classifier(name).fit(covs[::2], labels[::2])
    assert np.mean(clf.predict(covs[1::2]) == labels[1::2]) > 0.97
    d = clf.distances(covs[1::2])
    np.testing.assert_allclose(clf.certainty(covs[1::2]), d.mean(axis=1) - d.min(axis=1))
    again = type(clf).from_arrays(clf.classes_, clf.to_arrays())
    np.testing.assert_allclose(again.distances(covs[:5]), clf.distances(covs[:5]))


def test_mdm_and_fgmdm_match_pyriemann():
    rng = np.random.RandomState(1234)
    covs = make_matrices(60, 5, 'spd', rng)
    y = np.repeat([0, 1, 2], 20)
    ours = MdmClassifier().fit(covs, y)
    ref = MDM(metric='riemann').fit(covs, y)
    np.testing.assert_allclose(ours.distances(covs), ref.transform(covs), rtol=1e-6)
    fg = make_classifier('fgmdm').fit(covs, y)     # built from pyRiemann's public parts
    fg_ref = FgMDM(metric='riemann').fit(covs, y)
    np.testing.assert_array_equal(fg.predict(covs), fg_ref.predict(covs))
    np.testing.assert_allclose(fg.distances(covs), fg_ref.transform(covs), rtol=1e-6)


def test_certainty_formula():
    d = np.array([[1.0, 2.0, 3.0, 6.0], [0.5, 0.5, 0.5, 0.5]])
    np.testing.assert_allclose(certainty(d), [3.0 - 1.0, 0.0])


def test_training_reaches_near_perfect_accuracy(trained):
    model, report = trained
    assert report['accuracy'] >= 0.95
    assert report['n_trials'] == 32 and np.sum(report['confusion']) == 32
    assert set(report['certainty']) == {'left_hand', 'right_hand', 'both_hands', 'both_feet'}
    ev = evaluate(model, [make_recording(trials_per_class=5, seed=7)])
    assert ev['accuracy'] >= 0.95 and ev['balanced_accuracy'] >= 0.95


def test_online_decoder_equals_offline(trained):
    model, _ = trained
    rec = make_recording(trials_per_class=2, seed=3)
    filtered = filter_recording(model, rec.data, rec.channels, rec.rate)
    ends_online, d_online = stream_recording(model, rec, chunk=0.03)
    d_offline = decode_windows(model, window_covariances(model, filtered, ends_online))
    assert ends_online[0] == round(RATE) - 1
    assert np.all(np.diff(ends_online) == round(RATE / 16))
    np.testing.assert_allclose(d_online, d_offline, atol=1e-6)
    online = score_predictions(model, [rec], [(ends_online, d_online)])
    offline = evaluate(model, [rec])
    assert online['n_windows'] == offline['n_windows']
    assert online['window_accuracy'] == pytest.approx(offline['window_accuracy'])


def test_decoder_rejects_nan_and_flat_windows(trained):
    model, _ = trained
    rec = make_recording(trials_per_class=1, seed=4)
    dec = MiDecoder(model, rec.channels, rec.rate)
    data = rec.data.copy()
    data[300:310, 2] = np.nan
    out = dec.push(data[:600], 0)
    rejected = [r for r in out if isinstance(r, Rejected)]
    assert rejected and all('C5' in r.reason and 'NaN' in r.reason for r in rejected)
    assert isinstance(out[-1], Prediction)          # recovers once the NaN left the window
    flat = rec.data[600:1000].copy()
    flat[:, 5] = 1e-5
    out = dec.push(flat, 600)
    assert isinstance(out[-1], Rejected) and "Flat channels ['Cz']" in out[-1].reason


def test_decoder_gap_restarts_window(trained):
    model, _ = trained
    rec = make_recording(trials_per_class=1, seed=5)
    dec = MiDecoder(model, rec.channels, rec.rate)
    assert len(dec.push(rec.data[:200], 0)) > 0
    assert dec.push(rec.data[250:300], 250) == []       # gap of 50 samples: refill
    assert dec.samples_buffered == 50


def test_stream_mismatch_errors(trained):
    model, _ = trained
    with pytest.raises(ClassifierError, match=r'runs at 250\.0 Hz but the model was trained at'):
        MiDecoder(model, CHANNELS, 250.0)
    with pytest.raises(ClassifierError, match=r"needs the channels \['Cz'\]"):
        MiDecoder(model, [c for c in CHANNELS if c != 'Cz'], RATE)
    with pytest.raises(ClassifierError, match='no class means to adapt'):
        m = train([make_recording(trials_per_class=5, seed=0)],
                  TrainingConfig(pipeline='ts_lr', channels='all'), cross_validate=False)[0]
        MiDecoder(m, CHANNELS, RATE, AdaptationConfig(mode='supervised'))


def test_model_round_trip(tmp_path, trained):
    model, _ = trained
    path = model.save(tmp_path / 'm')
    assert path.name == 'm.json' and (tmp_path / 'm.npz').is_file()
    meta = json.loads(path.read_text())
    for key in ('classes', 'channels', 'rate', 'filter', 'window', 'pipeline', 'provenance',
                'versions'):
        assert key in meta
    assert meta['versions']['pyriemann']
    loaded = MiModel.load(tmp_path / 'm.json')
    data = make_recording(trials_per_class=1, seed=9).data
    covs = window_covariances(model, filter_recording(model, data, CHANNELS, RATE),
                              np.array([500, 600]))
    np.testing.assert_allclose(decode_windows(loaded, covs), decode_windows(model, covs))
    assert loaded.channels == model.channels and loaded.classes == model.classes


def test_model_file_errors(tmp_path, trained):
    model, _ = trained
    with pytest.raises(ClassifierError, match='does not exist; train one'):
        MiModel.load(tmp_path / 'missing.json')
    path = model.save(tmp_path / 'm')
    (tmp_path / 'bad.json').write_text('{not json')
    with pytest.raises(ClassifierError, match='not valid JSON'):
        MiModel.load(tmp_path / 'bad.json')
    (tmp_path / 'other.json').write_text('{"format": "something"}')
    with pytest.raises(ClassifierError, match='is not a MIndGrasp MI model'):
        MiModel.load(tmp_path / 'other.json')
    npz = tmp_path / 'm.npz'
    npz.write_bytes(npz.read_bytes()[:-10] + b'0123456789')
    with pytest.raises(ClassifierError, match='does not match the checksum'):
        MiModel.load(path)
    npz.unlink()
    with pytest.raises(ClassifierError, match=r'is missing; keep the \.npz'):
        MiModel.load(path)
    meta = json.loads(path.read_text())
    meta['format_version'] = 99
    path.write_text(json.dumps(meta))
    with pytest.raises(ClassifierError, match='format version 99'):
        MiModel.load(path)


def test_pickle_free_arrays(tmp_path, trained):
    model, _ = trained
    model.save(tmp_path / 'm')
    with np.load(tmp_path / 'm.npz', allow_pickle=False) as z:
        assert all(z[k].dtype != object for k in z.files)


def test_too_few_trials_error():
    rec = make_recording(classes=(0, 1), trials_per_class=3, seed=0)
    with pytest.raises(ClassifierError,
                       match=r"Too few trials per class to train: "
                             r"\{'left_hand': 3, 'right_hand': 3\}"):
        train([rec], TrainingConfig(channels='all'))
    with pytest.raises(ClassifierError, match='at least two classes'):
        train([make_recording(classes=(2,), trials_per_class=6)], TrainingConfig(channels='all'))


def test_oas_equals_pyriemann():
    from pyriemann.estimation import Covariances

    from mindgrasp_classifier.preprocessing import oas_covariances

    rng = np.random.RandomState(1234)
    x = rng.randn(6, 8, 100) * 5.0 + 2.0
    np.testing.assert_allclose(oas_covariances(x), Covariances(estimator='oas').transform(x),
                               rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize('name', PIPELINES)
def test_sklearn_pipeline_cross_validates(name):
    from sklearn.model_selection import cross_val_score

    from mindgrasp_classifier.pipelines import make_pipeline

    rng = np.random.RandomState(1234)
    mix = [np.diag(rng.uniform(0.3, 3.0, 6)) for _ in range(2)]
    x = np.array([mix[i % 2] @ rng.randn(6, 128) for i in range(40)])
    y = np.arange(40) % 2
    assert cross_val_score(make_pipeline(name), x, y, cv=4).mean() > 0.9
