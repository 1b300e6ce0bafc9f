"""``mindgrasp train vision``: collects, trains, reports and saves, deterministically."""

from __future__ import annotations

import json

import numpy as np
import pytest

from mindgrasp_cli.cli import main as mindgrasp
from mindgrasp_vision.commands.train_vision import split_indices
from mindgrasp_vision.shape_cnn import ShapeClassifier

pytestmark = pytest.mark.slow


def test_collects_trains_reports_and_saves(tmp_path, capsys):
    # (data set and training determinism are tested in test_shape_cnn.py)
    code = mindgrasp(['train', 'vision', '--n-images', '30', '--test-images', '0', '--epochs',
                      '1', '--seed', '5', '--quiet', '--json', '--output', str(tmp_path / 'm'),
                      '--dataset', str(tmp_path / 'data.npz')])
    out = capsys.readouterr().out
    assert code == 1   # one epoch on 24 images cannot reach the 95 % target: exit code 1
    assert 'Validation accuracy:' in out and 'target >= 95 %' in out
    figures = json.loads(out.strip().splitlines()[-1])
    assert (figures['n_images'], figures['n_train'], figures['n_val']) == (30, 24, 6)
    assert np.sum(figures['val_confusion']) == 6
    clf = ShapeClassifier.load(tmp_path / 'm')
    assert clf.training_['val_accuracy'] == figures['val_accuracy']
    meta = json.loads((tmp_path / 'm.json').read_text())
    assert meta['hyper_parameters']['seed'] == 5
    # the cached data set is reused
    assert (tmp_path / 'data.npz').is_file()
    assert mindgrasp(['train', 'vision', '--n-images', '30', '--test-images', '0', '--epochs',
                      '1', '--seed', '5', '--quiet', '--output', str(tmp_path / 'm2'),
                      '--dataset', str(tmp_path / 'data.npz')]) == 1
    assert 'Loaded 30 images from' in capsys.readouterr().out
    b = ShapeClassifier.load(tmp_path / 'm2')
    for va, vb in zip(clf.model_.state_dict().values(), b.model_.state_dict().values(),
                      strict=True):
        assert np.array_equal(va.numpy(), vb.numpy())   # same data, same seed, same weights


def test_bad_arguments_are_reported(capsys):
    assert mindgrasp(['train', 'vision', '--n-images', '5']) == 2
    assert '--n-images must be >= 30' in capsys.readouterr().err
    assert mindgrasp(['train', 'vision', '--realism', 'realistic']) == 2
    assert "--realism realistic: Unknown realism profile 'realistic'" in capsys.readouterr().err


def test_trains_on_noisy_images_with_a_realism_profile(tmp_path, capsys):
    code = mindgrasp(['train', 'vision', '--realism', 'default', '--n-images', '30',
                      '--test-images', '0', '--epochs', '1', '--seed', '6', '--quiet', '--json',
                      '--output', str(tmp_path / 'm'), '--dataset', str(tmp_path / 'd.npz')])
    out = capsys.readouterr().out
    assert code in (0, 1), out
    assert "realism 'default'" in out
    figures = json.loads(out.strip().splitlines()[-1])
    assert figures['realism'] == 'default' and figures['n_images'] == 30
    assert ShapeClassifier.load(tmp_path / 'm').training_['realism'] == 'default'


def test_split_is_stratified_and_seeded():
    y = np.repeat([0, 1, 2], 20)
    train, val = split_indices(y, 0.2, seed=1)
    assert np.bincount(y[val]).tolist() == [4, 4, 4]
    assert set(train).isdisjoint(val) and len(train) + len(val) == 60
    assert np.array_equal(split_indices(y, 0.2, seed=1)[1], val)
    assert not np.array_equal(split_indices(y, 0.2, seed=2)[1], val)
