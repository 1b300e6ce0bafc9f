"""Adaptive decoding on a session with synthetic drift (a changed electrode mixing)."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_classifier.decoder import AdaptationConfig, CueLabels
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.training import (
    TrainingConfig,
    evaluate,
    score_predictions,
    stream_recording,
    train,
)

from .classifier_synth import CHANNELS, make_recording


@pytest.fixture(scope='module')
def drifted():
    rng = np.random.RandomState(7)
    n = len(CHANNELS)
    drift = np.diag(np.exp(rng.uniform(-0.7, 0.7, n))) @ (np.eye(n) + 0.25 * rng.randn(n, n))
    model, _ = train([make_recording(trials_per_class=8, seed=0)], TrainingConfig(channels='all'),
                     cross_validate=False)
    return model, make_recording(trials_per_class=5, seed=11, drift=drift)


def _online_accuracy(model, rec, cfg, supervised=False):
    ends, dist = stream_recording(model, rec, cfg, supervised_labels=supervised)
    return score_predictions(model, [rec], [(ends, dist)])['window_accuracy']


def test_adaptation_helps_on_drift(drifted):
    model, rec = drifted
    before = model.classifier.covmeans_.copy()
    static = _online_accuracy(model, rec, AdaptationConfig())
    recentred = _online_accuracy(model, rec, AdaptationConfig(recenter='adaptive'))
    supervised = _online_accuracy(model, rec, AdaptationConfig(mode='supervised', rate=0.02),
                                  supervised=True)
    unsupervised = _online_accuracy(
        model, rec, AdaptationConfig(mode='unsupervised', rate=0.002, min_certainty=0.25,
                                     recenter='adaptive'))
    assert static < 0.85
    assert recentred > static + 0.1
    assert supervised > static + 0.1
    assert unsupervised > static + 0.1
    # the model itself is never changed by a decoder's adaptation
    assert np.array_equal(model.classifier.covmeans_, before)


def test_session_recentering_offline(drifted):
    model, rec = drifted
    fixed = evaluate(model, [rec])
    session = evaluate(model, [rec], recenter='session')
    assert session['window_accuracy'] > fixed['window_accuracy'] + 0.1


def test_cue_labels_cover_the_training_epoch():
    cues = CueLabels(0.5, 2.5)
    cues.add(10.0, 3)
    assert cues.label(10.5, 11.5) == 3 and cues.label(11.5, 12.5) == 3
    assert cues.label(10.4, 11.4) is None and cues.label(11.6, 12.6) is None


def test_bad_adaptation_settings():
    with pytest.raises(ClassifierError, match="Unknown adaptation mode 'sometimes'"):
        AdaptationConfig(mode='sometimes').check()
    with pytest.raises(ClassifierError, match=r'adaptation rate must lie in \[0, 1\]; 2'):
        AdaptationConfig(rate=2.0).check()
