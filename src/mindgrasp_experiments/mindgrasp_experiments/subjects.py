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
``eegmmidb:<subject>`` or ``path/to/subject.yaml``
    The replay subject: the virtual subject pursues the target as ``virtual`` does, but the EEG it
    streams is real (imagery epochs of the intended class from the subject's play recordings,
    stitched with rest; :class:`mindgrasp_eeg.replay_eeg.ReplayEEG`), decoded by a classifier that
    :func:`replay_model` calibrates on the subject's calibration recordings. EEGMMIDB subjects are
    built in; a subject file names any recordings (:mod:`mindgrasp_eeg.subject_file`).
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from collections.abc import Sequence

    from mindgrasp_common.types import Recording
    from mindgrasp_eeg.subject_file import ReplayFile, SubjectFiles

__all__ = ['SUBJECTS', 'is_replay', 'labelled_recordings', 'noise_model', 'replay_model']

SUBJECTS = ('noise', 'virtual', 'oracle', 'autonomous')

#: how :func:`replay_model` calibrates a replay subject's decoder: the four imagery classes and
#: rest, tangent space + logistic regression on 2 s windows of the epochs 0.5-4 s after each cue
#: (chosen by measurement on real EEG, src/mindgrasp_classifier/README.md: both hands against
#: both feet, the scan paradigm's decision, 94 % balanced on held-out runs, against 84 % with
#: 1 s windows); ``REPLAY_TAG`` names the cached model file, so a change here calibrates anew
REPLAY_TRAINING = {'pipeline': 'ts_lr', 'classes': [0, 1, 2, 3, 4], 'window': 2.0,
                   'tmin': 0.5, 'tmax': 4.0}
REPLAY_TAG = 'tslr_rest_w2_pair1'


def is_replay(subject: str) -> bool:
    """A replay subject (``eegmmidb:<subject>`` or a subject file ``*.yaml``)?"""
    from mindgrasp_eeg.subject_file import is_replay_source

    return is_replay_source(subject)


def replay_model(subject: str | SubjectFiles, directory: str | Path, *,
                 target_wrong_rate: float | None = None) -> Path:
    """Calibrate (once) the decoder (:data:`REPLAY_TRAINING`) of a replay subject
    (``eegmmidb:<n>``, a subject file's path or its
    :class:`~mindgrasp_eeg.subject_file.SubjectFiles`) on its calibration recordings, never the
    ones played in the loop, and save it in ``directory`` as
    ``<name>_classifier_<digest>_<REPLAY_TAG>.json`` (+ .npz); returns the .json path.

    The digest (12 hex digits of :meth:`SubjectFiles.calibration_digest`) changes with the
    calibration files, their event maps and the channel selection, so a cached model is reused
    only for the same calibration. The whole subject is checked first (both sets loadable, one
    channel layout and rate, enough epochs of every class and of rest to play), so its problems
    surface here as one :class:`~mindgrasp_eeg.EEGError` line, before any node starts.

    The model also gets the person's answer pair, decision thresholds (to ``target_wrong_rate``,
    default :data:`mindgrasp_classifier.answer_pair.TARGET_WRONG_RATE`) and calibration gate
    (:func:`mindgrasp_classifier.gate.calibrate_answer`), from the calibration recordings held
    out run by run; the pairs are restricted to the classes the play recordings hold.
    """
    from mindgrasp_classifier.answer_pair import TARGET_WRONG_RATE
    from mindgrasp_classifier.errors import ClassifierError
    from mindgrasp_classifier.training import TrainingConfig, train
    from mindgrasp_common.mi import DECODER_CLASS_NAMES
    from mindgrasp_eeg import EEGError
    from mindgrasp_eeg.replay_eeg import ReplayEEG
    from mindgrasp_eeg.subject_file import check_layout, replay_subject

    files = replay_subject(subject) if isinstance(subject, str) else subject
    rate = TARGET_WRONG_RATE if target_wrong_rate is None else float(target_wrong_rate)
    tag = REPLAY_TAG if rate == TARGET_WRONG_RATE else f'{REPLAY_TAG}_w{rate:g}'
    json_path = (Path(directory) /
                 f'{files.name}_classifier_{files.calibration_digest()[:12]}_{tag}.json')
    if json_path.exists():
        return json_path
    calibration, play = files.recordings('calibration'), files.recordings('play')
    check_layout([*calibration, *play], files.source)
    player = ReplayEEG.from_subject(files, recordings=play)   # enough epochs to play?
    labelled = labelled_recordings(files.calibration, calibration)
    cfg = TrainingConfig(**REPLAY_TRAINING,
                         channels=files.channels if isinstance(files.channels, str)
                         else list(files.channels))
    counts = {name: sum(int((r.events[:, 1] == c).sum()) for r in labelled)
              for c, name in enumerate(DECODER_CLASS_NAMES)}
    few = {name: n for name, n in counts.items() if n < cfg.min_trials}
    if few:
        msg = (f'The replay subject {files.source} has too few calibration epochs: {few} (at '
               f'least {cfg.min_trials} of every class are needed); give calibration recordings '
               'with more trials of every class (and their annotations in the event map).')
        raise EEGError(msg)
    try:
        model, _report = train(labelled, cfg)
    except ClassifierError as exc:      # e.g. too few motor channels: name the subject file key
        msg = (f'Cannot calibrate the replay subject {files.source}: {exc} (in a subject file: '
               'the channels: key).')
        raise EEGError(msg) from None
    from mindgrasp_classifier.gate import calibrate_answer

    entries = calibrate_answer(labelled, cfg, play_classes=set(player.classes),
                               target_wrong_rate=rate, temperature=model.temperature)
    model.answer_pair = entries['answer_pair']
    model.decision_thresholds = entries['decision_thresholds']
    model.gate = entries['gate']
    model.provenance['generator'] = (
        f'mindgrasp_experiments.subjects.replay_model({files.source}): calibration '
        f'{[f.entry for f in files.calibration]}')
    json_path.parent.mkdir(parents=True, exist_ok=True)
    return Path(model.save(json_path.with_suffix('')))


def labelled_recordings(files: Sequence[ReplayFile], recordings: Sequence[Recording]
                        ) -> list[Recording]:
    """``recordings`` (of the replay ``files``) with their cues: the onsets of the class epochs
    and of the rest epochs (class REST: the decoder says "nothing meant" instead of guessing an
    imagery class); training windows lie in each epoch's [tmin, tmax] (REPLAY_TRAINING)."""
    from mindgrasp_common.mi import REST
    from mindgrasp_eeg.replay_eeg import segments

    labelled = []
    for f, rec in zip(files, recordings, strict=True):
        events = [(k0, REST if cls is None else cls) for k0, _k1, cls in segments(rec, f.events)]
        labelled.append(replace(rec, events=np.array(events, dtype=int).reshape(-1, 2)))
    return labelled


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
