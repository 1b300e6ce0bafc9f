"""The demo's default model (mindgrasp_classifier models/default_classifier.json) and the script
that trains it."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from mindgrasp_classifier.decoder import MiDecoder, check_classes
from mindgrasp_classifier.model import CLASS_NAMES, DEFAULT_MODEL, MiModel
from mindgrasp_classifier.training import evaluate
from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE

REPO = Path(__file__).resolve().parents[2]


def _script():
    spec = importlib.util.spec_from_file_location(
        'train_default_classifier', REPO / 'scripts' / 'train_default_classifier.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_default_model_fits_the_demo_stream():
    model = MiModel.load(DEFAULT_MODEL)
    check_classes(model, CLASS_NAMES)
    assert model.rate == NAUTILUS_RATE and set(model.channels) <= set(NAUTILUS_32)
    MiDecoder(model, NAUTILUS_32, NAUTILUS_RATE)          # no mismatch with the virtual amp
    assert model.provenance['cross_validation']['accuracy'] >= 0.8


@pytest.mark.slow
def test_default_model_decodes_a_new_virtual_session():
    model = MiModel.load(DEFAULT_MODEL)
    session = _script().calibration_session(trials_per_class=3, seed=7)
    report = evaluate(model, [session])
    assert report['n_trials'] == 12 and report['accuracy'] >= 0.75   # chance 25 %
