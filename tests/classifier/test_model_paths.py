"""One resolver for model paths: ``package://<package>/<path>``, a data file of the package, or a
path from the working directory, in the offline and the live evaluation alike (``--live`` looked
for ``<cwd>/package:/...``)."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel, resolve_model_path
from mindgrasp_common.resources import resource_path

from .classifier_synth import make_recording
from .test_data_cli import write_run_bag

URI = 'package://mindgrasp_classifier/models/default_classifier'


def test_every_form_resolves_to_the_same_absolute_json(tmp_path, monkeypatch):
    shipped = resource_path('mindgrasp_classifier', 'models', 'default_classifier.json')
    assert resolve_model_path(URI) == shipped.absolute()
    assert resolve_model_path(URI + '.json') == shipped.absolute()
    assert resolve_model_path('models/default_classifier') == shipped.absolute()
    monkeypatch.chdir(tmp_path)
    (tmp_path / 'mine.json').write_text('{}')
    assert resolve_model_path('mine') == tmp_path / 'mine.json'
    with pytest.raises(ClassifierError, match="has no data file 'models/nope'"):
        resolve_model_path('package://mindgrasp_classifier/models/nope')


@pytest.mark.slow
def test_live_evaluation_takes_a_package_uri(tmp_path):
    model = MiModel.load(URI)
    rec = make_recording(classes=(0, 1), trials_per_class=1, seed=3, rate=model.rate,
                         channels=list(model.channels))           # 12 s, played in real time
    bag = write_run_bag(tmp_path / 'run', rec, drop=())
    out = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'evaluate', 'classifier',
                          '--model', URI, '--bag', str(bag), '--live', '--json', '--no-progress'],
                         capture_output=True, text=True, timeout=400, env=dict(os.environ),
                         cwd=tmp_path)
    assert out.returncode == 0, out.stdout[-3000:] + out.stderr[-3000:]
    assert 'package:' not in out.stderr
    live = json.loads(out.stdout.strip().splitlines()[-1])['live']
    assert live['n_predictions'] > 0
