"""The subjects of the experiments and what each needs.

``noise``
    The paper's unworn-cap control: EEG without imagery, decoded by a classifier that was trained
    on noise (as the paper's was). :func:`noise_model` trains that model on a Graz-BCI calibration
    of the virtual amplifier's noise (labels from the cue schedule, no imagery) and caches it.
``virtual``
    The virtual subject pursues the target at an accuracy; the default classifier was calibrated
    on the same simulated subject (head model) with another seed.
``oracle``
    No EEG: the subject's intended class is the prediction (``oracle_subject_node``).
``autonomous``
    No BCI (random locations).
``eegmmidb:<subject>``
    The replay subject: the virtual subject pursues the target as ``virtual`` does, but the EEG it
    streams is real (EEGMMIDB imagery epochs of the intended class, stitched with rest;
    :class:`mindgrasp_eeg.replay_eeg.ReplayEEG`), decoded by a classifier that
    :func:`replay_model` calibrates on other runs of the same subject.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ['SUBJECTS', 'is_replay', 'noise_model', 'replay_model']

SUBJECTS = ('noise', 'virtual', 'oracle', 'autonomous')


def is_replay(subject: str) -> bool:
    """A replay subject (``eegmmidb:<subject>``)?"""
    return subject.lower().startswith('eegmmidb:')


def replay_model(source: str, path: str | Path) -> Path:
    """Calibrate (once) an MDM for the replay subject ``source`` (``eegmmidb:<n>``) on its
    calibration runs (:data:`~mindgrasp_eeg.replay_eeg.EEGMMIDB_CALIBRATION_RUNS`, never the runs
    played in the loop) and save it as ``path`` (.json + .npz); returns the .json path."""
    from mindgrasp_classifier.data import eegbci_files, load_edf
    from mindgrasp_classifier.training import TrainingConfig, train
    from mindgrasp_eeg.replay_eeg import EEGMMIDB_CALIBRATION_RUNS, parse_replay_source

    subject = parse_replay_source(source)
    path = Path(path).with_suffix('')
    json_path = path.with_suffix('.json')
    if json_path.exists():
        return json_path
    recordings = [load_edf(f) for f in eegbci_files(subject, EEGMMIDB_CALIBRATION_RUNS)]
    model, _report = train(recordings, TrainingConfig(pipeline='mdm', channels='motor'))
    model.provenance['generator'] = (f'mindgrasp_experiments.subjects.replay_model({source}): '
                                     f'EEGMMIDB runs {list(EEGMMIDB_CALIBRATION_RUNS)}')
    path.parent.mkdir(parents=True, exist_ok=True)
    return Path(model.save(path))


def noise_model(path: str | Path, *, trials_per_class: int = 20, seed: int = 100,
                head_seed: int = 0) -> Path:
    """Train (once) an MDM on labelled noise and save it as ``path`` (.json + .npz); returns
    the .json path. Labels follow a Graz schedule (2 s fixation, 4 s cue, 2 s rest)."""
    from mindgrasp_classifier.data import Recording
    from mindgrasp_classifier.training import TrainingConfig, train
    from mindgrasp_eeg.montage import NAUTILUS_32, NAUTILUS_RATE
    from mindgrasp_eeg.synthetic import SyntheticEEG

    path = Path(path).with_suffix('')
    json_path = path.with_suffix('.json')
    if json_path.exists():
        return json_path
    rate = NAUTILUS_RATE
    rng = np.random.default_rng(seed)
    order = rng.permutation(np.repeat(np.arange(4), trials_per_class))
    trial_s = 8.0
    gen = SyntheticEEG(list(NAUTILUS_32), rate, seed=seed, head_seed=head_seed)
    data = gen.generate(round(len(order) * trial_s * rate), None)     # no imagery at all
    events = np.array([(round((i * trial_s + 2.0) * rate), int(c)) for i, c in enumerate(order)],
                      dtype=int)
    rec = Recording(data=data, rate=rate, channels=list(NAUTILUS_32), events=events,
                    source=f'virtual amplifier noise, Graz labels (seed {seed})')
    model, _report = train([rec], TrainingConfig(pipeline='mdm', channels='motor'))
    model.provenance['generator'] = 'mindgrasp_experiments.subjects.noise_model'
    path.parent.mkdir(parents=True, exist_ok=True)
    return Path(model.save(path))
