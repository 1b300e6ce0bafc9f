"""From a subject's runs to labelled covariance items: the *paradigm* step, in MOABB's sense.

:func:`eegmmidb_runs` loads the EEGMMIDB imagery runs of a subject that are on disk (through
MNE's eegbci loader, ``MNE_DATASETS_EEGBCI_PATH``; a run that is not there is left out, never
downloaded), labelled 0..3 with rest (``T0``) as :data:`~mindgrasp_common.mi.REST`.
:func:`trials_of` filters each run, cuts one epoch per cue and turns each epoch (or each
sliding window inside it) into a covariance matrix (:class:`Epoching` says how), giving the
:class:`~mindgrasp_classifier.evaluation.Trials` that :mod:`~mindgrasp_classifier.evaluation`
scores. Two epochings matter here:

- :data:`MOABB_PHYSIONET`: MOABB's ``MotorImagery`` paradigm on ``PhysionetMI`` (8-32 Hz,
  4th-order Butterworth forward-backward as MNE's ``filter(method='iir')``, epoch 0-3 s after
  the cue, every EEG channel, OAS covariance of the epoch, µV);
- the decoder's (:func:`decoder_epoching`): causal 4th-order Butterworth, motor-strip channels,
  windows of the training configuration stepping through the epoch, as
  :mod:`mindgrasp_classifier.training` cuts them.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.evaluation import Trials
from mindgrasp_common.types import Recording

__all__ = ['MOABB_PHYSIONET', 'Epoching', 'decoder_epoching', 'eegmmidb_runs', 'local_runs',
           'trials_of']


@dataclass(frozen=True)
class Epoching:
    """How a run becomes covariance items (times in s after the cue, frequencies in Hz).

    Attributes
    ----------
    band : (float, float)
        Band-pass edges.
    causal : bool
        The decoder's causal Butterworth of ``order`` (True) or forward-backward (False: MNE's
        ``filter(method='iir')``, as MOABB filters).
    order : int
    channels : 'motor', 'all' or tuple of str
        :func:`~mindgrasp_classifier.preprocessing.select_channels`.
    tmin, tmax : float
        The epoch.
    window : float or None
        Length of the windows stepping through the epoch (s), or None for one item per epoch.
    step : float
        Step between windows (s).
    """

    band: tuple[float, float] = (8.0, 30.0)
    causal: bool = True
    order: int = 4
    channels: str | tuple[str, ...] = 'motor'
    tmin: float = 0.5
    tmax: float = 2.5
    window: float | None = None
    step: float = 1.0 / 16.0


#: MOABB's MotorImagery paradigm on PhysionetMI (fmin 8, fmax 32, interval [0, 3] s)
MOABB_PHYSIONET = Epoching(band=(8.0, 32.0), causal=False, channels='all', tmin=0.0, tmax=3.0)


def decoder_epoching(**training: object) -> Epoching:
    """The epoching of :class:`~mindgrasp_classifier.training.TrainingConfig` (its defaults,
    updated by ``training``, e.g. ``window=2.0, tmax=4.0``): windows of ``window`` s every
    ``train_step`` s inside ``tmin``-``tmax``."""
    from mindgrasp_classifier.training import TrainingConfig

    keys = {'window', 'tmin', 'tmax', 'band', 'filter_order', 'channels', 'train_step'}
    cfg = TrainingConfig(**{k: v for k, v in training.items() if k in keys})
    channels = cfg.channels if isinstance(cfg.channels, str) else tuple(cfg.channels)
    return Epoching(band=tuple(cfg.band), causal=True, order=cfg.filter_order,
                    channels=channels, tmin=cfg.tmin, tmax=cfg.tmax, window=cfg.window,
                    step=cfg.train_step)


def local_runs(subject: int, runs: Sequence[int], path: str | None = None) -> list[int]:
    """The ``runs`` of EEGMMIDB ``subject`` whose files are in ``path`` (default
    ``MNE_DATASETS_EEGBCI_PATH``), in MNE's layout."""
    root = path or os.environ.get('MNE_DATASETS_EEGBCI_PATH')
    if not root:
        msg = ('MNE_DATASETS_EEGBCI_PATH is not set; set it to the folder that holds '
               'MNE-eegbci-data (e.g. ../shared/data).')
        raise ClassifierError(msg)
    folder = Path(root) / 'MNE-eegbci-data' / 'files' / 'eegmmidb' / '1.0.0' / f'S{subject:03d}'
    return [r for r in runs if (folder / f'S{subject:03d}R{r:02d}.edf').is_file()]


def eegmmidb_runs(subject: int, runs: Sequence[int] | None = None,
                  path: str | None = None) -> tuple[list[Recording], list[int]]:
    """The labelled imagery runs of an EEGMMIDB subject that are on disk.

    Returns
    -------
    recordings : list of Recording
        Volts, 160 Hz, 64 channels (10-10 names); events: cues 0..3 and rest (``T0``).
    runs : list of int
        Their run numbers.

    Raises
    ------
    ClassifierError
        None of the runs is on disk.
    """
    from mindgrasp_classifier.data import EEGMMIDB_IMAGERY_RUNS, eegbci_files, load_edf

    wanted = list(runs or EEGMMIDB_IMAGERY_RUNS)
    present = local_runs(subject, wanted, path)
    if not present:
        msg = (f'EEGMMIDB subject {subject} has none of the imagery runs {wanted} in '
               f'{path or os.environ.get("MNE_DATASETS_EEGBCI_PATH")}; see '
               '../shared/data/EEGMMIDB-README.md for the subjects there.')
        raise ClassifierError(msg)
    files = eegbci_files(subject, present, path)
    return [load_edf(f, rest=True) for f in files], present


def _filtered(rec: Recording, epoching: Epoching) -> tuple[np.ndarray, list[str]]:
    """The run's chosen channels, band-passed, in µV; shape (n_samples, n_channels)."""
    from scipy.signal import sosfiltfilt

    from mindgrasp_classifier.preprocessing import (
        CausalBandpass,
        channel_indices,
        design_bandpass,
        select_channels,
    )

    channels = select_channels(rec.channels, epoching.channels if isinstance(
        epoching.channels, str) else list(epoching.channels))
    x = np.asarray(rec.data, dtype=float)[:, channel_indices(rec.channels, channels)] * 1e6
    sos = design_bandpass(*epoching.band, rec.rate, epoching.order)
    if epoching.causal:
        return CausalBandpass(sos, len(channels)).process(x), channels
    return sosfiltfilt(sos, x, axis=0), channels


def trials_of(recordings: Sequence[Recording], epoching: Epoching) -> Trials:
    """Covariance items of every cue of ``recordings`` (one run each).

    Parameters
    ----------
    recordings : sequence of Recording
        Volts; ``events`` rows ``(onset sample, label 0..3 or REST)``.
    epoching : Epoching

    Returns
    -------
    Trials
        OAS covariances (µV²) of each epoch or window; a cue whose epoch runs past the end of
        its recording, or holds lost (non-finite) samples, is left out.
    """
    from mindgrasp_classifier.preprocessing import (
        extract_windows,
        oas_covariances,
        step_samples,
        window_ends,
        window_samples,
    )

    covs, item_trial, labels, runs = [], [], [], []
    channels: list[str] = []
    for r, rec in enumerate(recordings):
        filtered, channels = _filtered(rec, epoching)
        bad_before = np.concatenate([[0], np.cumsum(~np.isfinite(filtered).all(axis=1))])
        fs = rec.rate
        for onset, label in rec.events:
            start = int(onset) + round(epoching.tmin * fs)
            stop = int(onset) + round(epoching.tmax * fs)
            if start < 0 or stop > len(filtered) or bad_before[stop] != bad_before[start]:
                continue
            if epoching.window is None:
                n_window, ends = stop - start, np.array([stop - 1])
            else:
                n_window = window_samples(fs, epoching.window)
                ends = window_ends(start, stop, n_window, step_samples(fs, epoching.step))
            if len(ends) == 0:
                continue
            covs.append(oas_covariances(extract_windows(filtered, ends, n_window)))
            item_trial += [len(labels)] * len(ends)
            labels.append(int(label))
            runs.append(r)
    n = len(channels)
    return Trials(covs=np.concatenate(covs) if covs else np.zeros((0, n, n)),
                  item_trial=np.array(item_trial, dtype=int),
                  labels=np.array(labels, dtype=int), runs=np.array(runs, dtype=int),
                  channels=list(channels))
