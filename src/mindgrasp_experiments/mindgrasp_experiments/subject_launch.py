"""What a subject of an experiment adds to the experiment profile's launch arguments.

The domain's side of ``--subject``: :class:`~mindgrasp_experiments.experiment.Experiment` and the
sweep verb ask :func:`subject_launch_args` which classifier model and EEG source a subject
brings; nothing here reads a command line.
"""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ['noise_model_path', 'subject_launch_args']


def noise_model_path(fallback_dir: Path) -> str:
    """The packaged noise-trained model, else one trained now into ``fallback_dir``."""
    from mindgrasp_common.resources import ResourceNotFoundError, resource_path

    try:
        return str(resource_path('mindgrasp_classifier', 'models', 'noise_classifier.json'))
    except ResourceNotFoundError:
        from mindgrasp_experiments.subjects import noise_model

        print('Training the classifier on noise (once) ...', file=sys.stderr)
        return str(noise_model(fallback_dir / 'noise_classifier'))


def subject_launch_args(subject: str, out: Path) -> dict[str, str]:
    """The experiment profile's launch arguments for ``subject``: a replay subject
    (``eegmmidb:<n>`` or a subject file) is the pursuing virtual subject streaming that subject's
    real EEG, decoded by a model calibrated on its calibration recordings; a fitted virtual subject
    (``virtual:FILE.yaml``) is the virtual subject decoded by a model calibrated on its head
    (:func:`~mindgrasp_experiments.fitted_subject.fitted_model`, cached); the noise subject
    gets the noise-trained model."""
    from mindgrasp_experiments.fitted_subject import fitted_model, is_fitted, load_fitted
    from mindgrasp_experiments.subjects import is_replay, replay_model

    if is_fitted(subject):
        import shutil

        model = fitted_model(load_fitted(subject))
        for suffix in ('.json', '.npz'):    # a copy in the run: it names the decoder it used
            shutil.copy2(model.with_suffix(suffix), out / model.with_suffix(suffix).name)
        return {'subject': 'virtual', 'model': str(out / model.name)}
    if is_replay(subject):
        from mindgrasp_eeg.subject_file import replay_subject

        files = replay_subject(subject)
        print(f'Calibrating the classifier on {files.name} (once) ...', file=sys.stderr)
        model = replay_model(files, out)
        return {'subject': 'virtual', 'eeg_source': files.source, 'model': str(model)}
    if subject == 'noise':
        return {'subject': 'noise', 'model': noise_model_path(out)}
    return {'subject': subject}
