"""Decodability's paradigm: labelled runs, the electrodes both subjects share, one re-centred
covariance per cue, and the cue schedules a virtual subject imagines.

Each recording is band-passed (8-30 Hz, causal 4th-order Butterworth, as the online decoder),
cut into one epoch per cue (0.5-2.5 s after it), each epoch gives an OAS covariance, and the
covariances of a recording are re-centred on their Riemannian mean (unsupervised, per
recording: what makes calibration and test runs comparable).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from mindgrasp_common.mi import REST
from mindgrasp_common.types import Recording
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import BOTH_FEET, BOTH_HANDS, LEFT_HAND, NAUTILUS_32, RIGHT_HAND

__all__ = ['MAX_IMAGERY_S', 'MeasureConfig', 'RunSchedule', 'common_channels',
           'eegmmidb_like_schedules', 'epoch_covariances', 'labelled']

#: longest imagery of a cue without a following cue (s); EEGMMIDB cues last 4.1 s
MAX_IMAGERY_S = 4.1
#: classifiers of every figure: pyRiemann MDM, tangent space + logistic regression
PIPELINES = ('mdm', 'ts_lr')


@dataclass(frozen=True)
class MeasureConfig:
    """Preprocessing of :func:`~mindgrasp_experiments.decodability.measure` (times in s after
    the cue, frequencies in Hz).

    Attributes
    ----------
    band : (float, float)
        Band-pass edges.
    filter_order : int
        Butterworth order.
    tmin, tmax : float
        Epoch after each cue.
    pipelines : tuple of str
        Classifiers (:data:`PIPELINES`).
    """

    band: tuple[float, float] = (8.0, 30.0)
    filter_order: int = 4
    tmin: float = 0.5
    tmax: float = 2.5
    pipelines: tuple[str, ...] = PIPELINES


def labelled(recording: Recording, events: Mapping[str, int | None]) -> Recording:
    """A copy of ``recording`` whose ``events`` are its annotations in ``events`` (annotation ->
    class 0..3, None = rest), rest as :data:`REST`; epochs as the replay subject cuts them
    (:func:`~mindgrasp_eeg.replay_eeg.segments`)."""
    from mindgrasp_eeg.replay_eeg import segments

    rows = [(k0, REST if cls is None else int(cls)) for k0, _k1, cls in segments(recording, events)]
    return replace(recording, events=np.array(rows, dtype=int).reshape(-1, 2))


def common_channels(channels: Sequence[str]) -> list[str]:
    """The virtual amplifier's channels (:data:`~mindgrasp_eeg.montage.NAUTILUS_32`) that
    ``channels`` has, in that order, spelled as in ``channels``: both subjects are measured on
    the same electrodes.

    Raises
    ------
    EEGError
        Fewer than 8 of them, or C3, Cz or C4 missing.
    """
    lower = {c.lower(): c for c in channels}
    out = [lower[c.lower()] for c in NAUTILUS_32 if c.lower() in lower]
    missing = [c for c in ('C3', 'Cz', 'C4') if c.lower() not in lower]
    if missing or len(out) < 8:
        msg = (f'The recordings share only {len(out)} channels with the virtual amplifier '
               f'({out}; missing motor channels: {missing}); decodability needs C3, Cz, C4 and '
               f'at least 8 of {list(NAUTILUS_32)}.')
        raise EEGError(msg)
    return out


def epoch_covariances(recording: Recording, channels: Sequence[str],
                      config: MeasureConfig | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Re-centred OAS covariances of the labelled epochs of one recording.

    Parameters
    ----------
    recording : Recording
        Volts; ``events`` rows ``(onset sample, label 0..3 or REST)``.
    channels : sequence of str
        Channels used (names of ``recording.channels``).
    config : MeasureConfig

    Returns
    -------
    covs : ndarray, shape (n_epochs, n_channels, n_channels)
        Whitened by the recording's Riemannian mean (dimensionless; their mean is identity).
    labels : ndarray of int, shape (n_epochs,)
    """
    from pyriemann.geometry.base import invsqrtm
    from pyriemann.geometry.mean import mean_logeuclid, mean_riemann

    from mindgrasp_classifier.errors import ClassifierError
    from mindgrasp_classifier.preprocessing import (
        CausalBandpass,
        channel_indices,
        design_bandpass,
        extract_windows,
        oas_covariances,
    )

    cfg = config or MeasureConfig()
    try:
        idx = channel_indices(recording.channels, channels)
        sos = design_bandpass(*cfg.band, recording.rate, cfg.filter_order)
    except ClassifierError as exc:
        raise EEGError(f'{recording.source}: {exc}') from None
    x = np.asarray(recording.data, dtype=float)[:, idx]
    finite = np.isfinite(x).all(axis=1)
    # lost samples would ring through the filter for ever: filter zeros there, drop their epochs
    filtered = CausalBandpass(sos, len(idx)).process(np.where(finite[:, None], x, 0.0))
    bad_before = np.concatenate([[0], np.cumsum(~finite)])
    fs = recording.rate
    k0, k1 = round(cfg.tmin * fs), round(cfg.tmax * fs)
    starts = recording.events[:, 0] + k0
    stops = recording.events[:, 0] + k1
    ok = (starts >= 0) & (stops <= len(x))
    ok[ok] = bad_before[stops[ok]] == bad_before[starts[ok]]
    if ok.sum() < 2:
        return np.zeros((0, len(idx), len(idx))), np.zeros(0, dtype=int)
    covs = oas_covariances(extract_windows(filtered, stops[ok] - 1, k1 - k0))
    # the Riemannian mean, started at the log-Euclidean one: a few iterations instead of ~20
    white = invsqrtm(mean_riemann(covs, tol=1e-6, init=mean_logeuclid(covs)))
    return white @ covs @ white, recording.events[ok, 1].astype(int)


@dataclass(frozen=True)
class RunSchedule:
    """The cues of one run, to be imagined by the virtual subject.

    Attributes
    ----------
    duration : float
        Length of the run (s).
    cues : tuple of (float, int)
        ``(onset s, label)``, label 0..3 (imagined from the onset until the next cue, at most
        :data:`MAX_IMAGERY_S`) or :data:`REST`; sorted by onset.
    """

    duration: float
    cues: tuple[tuple[float, int], ...]

    @classmethod
    def of(cls, recording: Recording) -> RunSchedule:
        """The schedule of a labelled recording (:func:`labelled`)."""
        rows = sorted((int(k) / recording.rate, int(c)) for k, c in recording.events)
        return cls(recording.duration, tuple(rows))


def eegmmidb_like_schedules(seed: int = 0, trials: int = 15, *, cue_s: float = 4.1,
                            rest_s: float = 4.2) -> tuple[list[RunSchedule], list[RunSchedule]]:
    """A Graz-like protocol shaped as EEGMMIDB's imagery runs: calibration and test sessions of
    two runs each (left/right hand, then both hands/feet), ``trials`` cues per run in seeded
    random order, each cue (``cue_s``) after a rest period (``rest_s``, labelled rest)."""
    rng = np.random.default_rng([seed, 3])
    runs = []
    for pair in ((LEFT_HAND, RIGHT_HAND), (BOTH_HANDS, BOTH_FEET)) * 2:
        order = rng.permutation(np.resize(np.array(pair), trials))
        cues: list[tuple[float, int]] = []
        for i, cls in enumerate(order):
            t = i * (cue_s + rest_s)
            cues += [(t, REST), (t + rest_s, int(cls))]
        runs.append(RunSchedule(trials * (cue_s + rest_s) + rest_s, tuple(cues)))
    return runs[:2], runs[2:]
