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
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ['SUBJECTS', 'noise_model']

SUBJECTS = ('noise', 'virtual', 'oracle', 'autonomous')


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
