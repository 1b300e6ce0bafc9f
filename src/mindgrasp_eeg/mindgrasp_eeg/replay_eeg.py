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

EEGMMIDB (``eegmmidb:<subject>``): imagery runs 4, 8, 12 (T1 left fist -> left hand, T2 right fist
-> right hand) and 6, 10, 14 (T1 both fists -> both hands, T2 both feet -> both feet), T0 rest.
The loop plays :data:`EEGMMIDB_PLAY_RUNS`; the classifier is calibrated on
:data:`EEGMMIDB_CALIBRATION_RUNS` of the same subject, never on epochs played in the loop.
Files come through MNE's EEGMMIDB loader (``MNE_DATASETS_EEGBCI_PATH``, else it downloads).

    >>> import numpy as np
    >>> epochs = {None: [np.zeros((10, 2))], 0: [np.ones((4, 2))]}
    >>> gen = ReplayEEG(epochs, 160.0, ['C3', 'C4'], seed=0)
    >>> gen.generate(3, 0).shape
    (3, 2)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from mindgrasp_common.types import Recording

from . import EEGError

__all__ = ['EEGMMIDB_CALIBRATION_RUNS', 'EEGMMIDB_EVENTS', 'EEGMMIDB_PLAY_RUNS', 'MIN_EPOCHS',
           'ReplayEEG', 'eegmmidb_runs', 'epochs_of', 'parse_replay_source']

#: EEGMMIDB imagery run -> {annotation: MIndGrasp class}; T0 is rest in every run
EEGMMIDB_EVENTS: dict[int, dict[str, int]] = {
    **{r: {'T1': 0, 'T2': 1} for r in (4, 8, 12)},      # left fist, right fist
    **{r: {'T1': 2, 'T2': 3} for r in (6, 10, 14)},     # both fists, both feet
}
#: runs the classifier is calibrated on / runs played in the loop (disjoint)
EEGMMIDB_CALIBRATION_RUNS = (4, 6)
EEGMMIDB_PLAY_RUNS = (8, 10)
#: fewest recorded epochs of each class (and of rest) a replay subject needs
MIN_EPOCHS = 3
REST = 'T0'


def parse_replay_source(text: str) -> int:
    """``'eegmmidb:1'`` -> subject 1 (raises :class:`EEGError` naming the form)."""
    kind, _, subject = text.partition(':')
    if kind.lower() != 'eegmmidb' or not subject.strip().lstrip('Ss').isdigit():
        msg = (f'{text!r} is not a replay subject; write eegmmidb:<subject>, e.g. eegmmidb:1 '
               '(EEGMMIDB subjects 1-109).')
        raise EEGError(msg)
    number = int(subject.strip().lstrip('Ss'))
    if not 1 <= number <= 109:
        msg = f'{text!r}: EEGMMIDB has subjects 1-109; write e.g. eegmmidb:1.'
        raise EEGError(msg)
    return number


def eegmmidb_runs(subject: int, runs: Sequence[int]) -> list[Recording]:
    """The recordings of EEGMMIDB ``subject``'s ``runs`` (volts, standard 10-10 names, with
    their annotations), through MNE's loader."""
    from .player import expand_sources, load_recording

    try:
        paths = expand_sources([f"eegbci:{subject}:{','.join(str(r) for r in runs)}"])
    except EEGError:
        raise
    except Exception as exc:    # download or file errors from MNE/pooch
        msg = (f'MNE could not provide EEGMMIDB subject {subject} runs {list(runs)} '
               f'({type(exc).__name__}: {exc}); set MNE_DATASETS_EEGBCI_PATH to a folder that '
               'holds them, or allow the download.')
        raise EEGError(msg) from None
    return [load_recording(p) for p in paths]


def epochs_of(recording: Recording, events: Mapping[str, int]) -> dict[int | None, list]:
    """Epochs of ``recording`` by class (``None``: rest), from its annotations.

    Returns ``{class or None: [ndarray (n_samples, n_channels), volts, mean removed]}``."""
    out: dict[int | None, list] = {}
    for onset, duration, label in recording.annotations:
        if label == REST:
            cls = None
        elif label in events:
            cls = events[label]
        else:
            continue
        k0 = round(onset * recording.rate)
        k1 = min(len(recording.data), round((onset + duration) * recording.rate))
        if k1 - k0 < recording.rate:       # shorter than 1 s: a fragment at the end of the run
            continue
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
                 min_epochs: int = 1) -> None:
        self.sample_rate = float(sample_rate)
        self.channel_names = list(channel_names)
        for cls in (None, 0, 1, 2, 3):
            have = len(epochs.get(cls, ()))
            if have < min_epochs:
                name = 'rest' if cls is None else f'class {cls}'
                msg = (f'The replay subject has {have} recorded epoch(s) of {name}, fewer than '
                       f'{min_epochs}; give runs with more trials of every class (EEGMMIDB '
                       f'imagery runs {sorted(EEGMMIDB_EVENTS)}).')
                raise EEGError(msg)
        self.epochs = {cls: [np.asarray(e, dtype=float) for e in eps]
                       for cls, eps in epochs.items()}
        self._rng = np.random.default_rng(seed)
        self._queue: dict[int | None, list[int]] = {}
        self._class: object = 'unset'
        self._seg: np.ndarray | None = None
        self._pos = 0
        self.n_generated = 0
        self.n_played = {cls: 0 for cls in self.epochs}    # epochs started, per class

    @classmethod
    def eegmmidb(cls, subject: int, runs: Sequence[int] = EEGMMIDB_PLAY_RUNS, *,
                 seed: int = 0) -> ReplayEEG:
        """EEGMMIDB ``subject``'s imagery ``runs`` (disjoint from the calibration runs)."""
        bad = [r for r in runs if r not in EEGMMIDB_EVENTS]
        if bad:
            msg = (f'EEGMMIDB runs {bad} are not imagery runs; use runs of 4, 8, 12 (left/right '
                   'fist) and 6, 10, 14 (both fists/feet).')
            raise EEGError(msg)
        epochs: dict[int | None, list] = {}
        channels: list[str] | None = None
        rate = 0.0
        for run, rec in zip(runs, eegmmidb_runs(subject, runs), strict=True):
            channels, rate = channels or rec.channels, rec.rate
            for c, eps in epochs_of(rec, EEGMMIDB_EVENTS[run]).items():
                epochs.setdefault(c, []).extend(eps)
        return cls(epochs, rate, channels or [], seed=seed, min_epochs=MIN_EPOCHS)

    @property
    def n_channels(self) -> int:
        return len(self.channel_names)

    def _next_epoch(self, mi_class: int | None) -> np.ndarray:
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
