"""A subject made of real EEG: recorded imagery epochs of the intended class, stitched with rest.

:class:`ReplayEEG` has the generator interface of :class:`~mindgrasp_eeg.synthetic.SyntheticEEG`
(``generate(n_samples, mi_class)``, ``sample_rate``, ``channel_names``, ``n_channels``,
``n_generated``), so the :class:`~mindgrasp_eeg.virtual_amp.VirtualAmplifier` and the virtual
amplifier node drive it exactly as they drive the synthetic head: the virtual subject decides
the intent (``pursue`` as for the synthetic subject), and the EEG streamed while it intends a
class is a real imagery epoch of that class from the recordings; while it rests, a real rest
period. When the intent changes, the stream switches to the start of an epoch of the new class;
an intent held longer than one epoch continues with the next epoch of that class. Epochs of a
class are played in a seeded random order, cycling when all were played.

Each epoch has its per-channel mean removed, so the joins carry no DC steps (the recordings'
offsets differ from epoch to epoch; the decoder band-passes anyway).

Which recordings are played, and how their annotations map to classes, comes from a replay subject
description (:mod:`mindgrasp_eeg.subject_file`: ``eegmmidb:<n>`` or a subject file):
:meth:`ReplayEEG.from_source` plays its ``play`` set; the classifier is calibrated on its
``calibration`` set, never on the epochs played in the loop. An epoch is an annotation's duration,
or for markers without one (XDF string markers, many GDF cues) the time up to the next annotation
or the end of the file, at most :data:`MAX_EPOCH_S` (:func:`segments`).

    >>> import numpy as np
    >>> epochs = {None: [np.zeros((10, 2))], 0: [np.ones((4, 2))]}
    >>> gen = ReplayEEG(epochs, 160.0, ['C3', 'C4'], seed=0)
    >>> gen.generate(3, 0).shape
    (3, 2)
"""

from __future__ import annotations

import bisect
from collections.abc import Mapping, Sequence

import numpy as np

from mindgrasp_common.types import Recording

from . import EEGError
from .subject_file import SubjectFiles, replay_subject

__all__ = ['MAX_EPOCH_S', 'MIN_EPOCHS', 'ReplayEEG', 'epochs_of', 'segments']

#: fewest recorded epochs of each class (and of rest) a replay subject needs
MIN_EPOCHS = 3
#: longest epoch cut from a marker without duration (s): up to the next annotation, at most this
MAX_EPOCH_S = 4.0
#: shortest epoch kept (s): shorter ones are fragments at the end of a recording
MIN_EPOCH_S = 1.0


def segments(recording: Recording,
             events: Mapping[str, int | None]) -> list[tuple[int, int, int | None]]:
    """The labelled epochs of ``recording``: ``(first sample, end sample, class)`` per annotation
    in ``events`` (annotation -> class 0..3, None = rest), in the order of the annotations.

    An epoch lasts the annotation's duration; an annotation without one (a marker) lasts until
    the next annotation of any kind or the end of the data, at most :data:`MAX_EPOCH_S`. Epochs
    shorter than :data:`MIN_EPOCH_S` (a fragment at the end of a run) and epochs starting before
    the first sample are left out.
    """
    fs, n = recording.rate, len(recording.data)
    onsets = sorted(onset for onset, _d, _l in recording.annotations)
    out: list[tuple[int, int, int | None]] = []
    for onset, duration, label in recording.annotations:
        if label not in events:
            continue
        if duration > 0:
            end = onset + duration
        else:
            later = onsets[bisect.bisect_right(onsets, onset):]
            end = min(later[0] if later else n / fs, onset + MAX_EPOCH_S)
        k0, k1 = round(onset * fs), min(n, round(end * fs))
        if k0 >= 0 and k1 - k0 >= MIN_EPOCH_S * fs:    # (a marker before the first sample: out)
            out.append((k0, k1, events[label]))
    return out


def epochs_of(recording: Recording,
              events: Mapping[str, int | None]) -> dict[int | None, list[np.ndarray]]:
    """Epochs of ``recording`` by class (``None``: rest), cut by :func:`segments`.

    Returns ``{class or None: [ndarray (n_samples, n_channels), volts, mean removed]}``."""
    out: dict[int | None, list[np.ndarray]] = {}
    for k0, k1, cls in segments(recording, events):
        seg = np.asarray(recording.data[k0:k1], dtype=float)
        out.setdefault(cls, []).append(seg - seg.mean(axis=0))
    return out


class ReplayEEG:
    """Real EEG by intent, with the generator interface of ``SyntheticEEG``.

    Parameters
    ----------
    epochs : mapping class (0..3, None = rest) -> list of ndarray (n_samples, n_channels), volts
    sample_rate : float, Hz
    channel_names : list of str, n_channels
    seed : int
        Seed of the order in which each class's epochs are played.
    """

    def __init__(self, epochs: Mapping[int | None, Sequence[np.ndarray]], sample_rate: float,
                 channel_names: Sequence[str], *, seed: int = 0,
                 min_epochs: int = 1, source: str = '') -> None:
        self.sample_rate = float(sample_rate)
        self.channel_names = list(channel_names)
        where = f' {source}' if source else ''
        # an imagery class the recordings lack (EEGMMIDB S006-S012 play only run 12: left and
        # right hand) is one this subject cannot express: imagining it streams rest
        present = [c for c in (0, 1, 2, 3) if epochs.get(c)]
        for cls in (None, *(present if len(present) >= 2 else (0, 1, 2, 3))):
            have = len(epochs.get(cls, ()))
            if have < min_epochs:
                name = 'rest' if cls is None else f'class {cls}'
                msg = (f'The replay subject{where} has {have} recorded epoch(s) of {name}, fewer '
                       f'than {min_epochs}; give recordings with more trials of every class '
                       '(and their annotations in the event map).')
                raise EEGError(msg)
        self.epochs = {cls: [np.asarray(e, dtype=float) for e in eps]
                       for cls, eps in epochs.items() if len(eps)}
        #: the imagery classes the recordings hold (the others stream rest)
        self.classes = set(present)
        self._rng = np.random.default_rng(seed)
        self._queue: dict[int | None, list[int]] = {}
        self._class: object = 'unset'
        self._seg: np.ndarray | None = None
        self._pos = 0
        self.n_generated = 0
        self.n_played = {cls: 0 for cls in self.epochs}    # epochs started, per class

    @classmethod
    def from_subject(cls, subject: SubjectFiles, *, seed: int = 0,
                     recordings: Sequence[Recording] | None = None) -> ReplayEEG:
        """The ``play`` recordings of a replay subject (``recordings``: those files, already
        loaded by ``subject.recordings('play')``); needs :data:`MIN_EPOCHS` of each class and
        of rest."""
        recs = subject.recordings('play') if recordings is None else recordings
        epochs: dict[int | None, list[np.ndarray]] = {}
        for f, rec in zip(subject.play, recs, strict=True):
            for c, eps in epochs_of(rec, f.events).items():
                epochs.setdefault(c, []).extend(eps)
        return cls(epochs, recs[0].rate, recs[0].channels, seed=seed, min_epochs=MIN_EPOCHS,
                   source=subject.source)

    @classmethod
    def from_source(cls, source: str, *, seed: int = 0) -> ReplayEEG:
        """``eegmmidb:<n>`` or a subject file's path (:func:`~.subject_file.replay_subject`)."""
        return cls.from_subject(replay_subject(source), seed=seed)

    @property
    def n_channels(self) -> int:
        return len(self.channel_names)

    def _next_epoch(self, mi_class: int | None) -> np.ndarray:
        if mi_class not in self.epochs:
            mi_class = None             # a class the play data cannot express: rest
        queue = self._queue.get(mi_class)
        if not queue:
            queue = list(self._rng.permutation(len(self.epochs[mi_class])))
            self._queue[mi_class] = queue
        self.n_played[mi_class] += 1
        return self.epochs[mi_class][queue.pop()]

    def generate(self, n_samples: int, mi_class: int | None = None) -> np.ndarray:
        """The next ``n_samples`` of real EEG for ``mi_class`` (0..3, None = rest).

        Returns
        -------
        data : ndarray, shape (n_samples, n_channels), volts
        """
        if mi_class is not None and mi_class not in (0, 1, 2, 3):
            msg = f'mi_class must be 0..3 or None; {mi_class!r} is not a motor-imagery class.'
            raise EEGError(msg)
        out = np.empty((n_samples, self.n_channels))
        k = 0
        if mi_class != self._class:     # a new intent starts a fresh epoch of its class
            self._class, self._seg = mi_class, None
        while k < n_samples:
            if self._seg is None or self._pos >= len(self._seg):
                self._seg, self._pos = self._next_epoch(mi_class), 0
            take = min(n_samples - k, len(self._seg) - self._pos)
            out[k:k + take] = self._seg[self._pos:self._pos + take]
            k += take
            self._pos += take
        self.n_generated += n_samples
        return out
