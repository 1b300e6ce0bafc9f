"""Online MI decoding: chunks in, one prediction per window step out.

:class:`MiDecoder` keeps the causal filter state, a buffer of filtered samples, the adaptive
re-centering reference and (optionally adapted) class means. Offline tools call
:func:`filter_recording` and :func:`decode_windows`, which use the same filter class, the same
window grid and the same covariance/distance code, so online and offline results agree.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import DECODER_CLASS_NAMES, SCALE_V_TO_UV, MiModel
from mindgrasp_classifier.pipelines import certainty as certainty_of
from mindgrasp_classifier.pipelines import riemann_mean
from mindgrasp_classifier.preprocessing import (
    CausalBandpass,
    channel_indices,
    design_bandpass,
    extract_windows,
    step_samples,
    window_samples,
)
from mindgrasp_common.mi import REST
from mindgrasp_common.types import Prediction

ADAPT_MODES = ('none', 'supervised', 'unsupervised', 'both')
RECENTER_MODES = ('fixed', 'adaptive')


@dataclass
class Rejected:
    """A window that produced no prediction, with the reason as a full sentence."""

    sample_index: int
    reason: str


@dataclass
class AdaptationConfig:
    """How a decoder adapts during a session.

    Attributes
    ----------
    mode : str
        ``none``; ``supervised`` (class means move towards windows labelled by trainer prompts);
        ``unsupervised`` (towards windows predicted with certainty >= ``min_certainty``);
        ``both`` (supervised while a label is set, unsupervised otherwise).
    rate : float
        Geodesic step (0..1) of a class mean per window.
    min_certainty : float
        Certainty needed for an unsupervised update.
    recenter : str
        ``fixed`` keeps the training reference; ``adaptive`` tracks the session's Riemannian mean
        (a cumulative mean at first, then exponential forgetting at ``recenter_rate``).
    recenter_rate : float
        Smallest weight (0..1) of a new window in the running reference.
    recenter_prior : float
        Seconds of windows the training reference counts for in the running reference when
        adaptive re-centering starts, so the first windows of a session do not decide it alone
        (0: the first window replaces it).

    Notes
    -----
    Unsupervised mean updates need ``recenter='adaptive'`` when the session has drifted: without
    re-centering, drifted windows are confidently assigned to one class, whose mean then absorbs
    everything (see ``benchmarks/classifier.py``, section adaptation).
    """

    mode: str = 'none'
    rate: float = 0.005
    min_certainty: float = 0.5
    recenter: str = 'fixed'
    recenter_rate: float = 0.005
    recenter_prior: float = 0.0

    def check(self) -> None:
        """Raise :class:`ClassifierError` on an invalid setting."""
        if self.mode not in ADAPT_MODES:
            msg = f'Unknown adaptation mode {self.mode!r}; choose one of {list(ADAPT_MODES)}.'
            raise ClassifierError(msg)
        if self.recenter not in RECENTER_MODES:
            msg = (f'Unknown re-centering mode {self.recenter!r}; choose one of '
                   f'{list(RECENTER_MODES)}.')
            raise ClassifierError(msg)
        for name in ('rate', 'recenter_rate'):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                msg = f'The adaptation {name} must lie in [0, 1]; {value} is invalid.'
                raise ClassifierError(msg)
        if not 0.0 <= self.recenter_prior < float('inf'):
            msg = (f'recenter_prior must be a finite number of seconds >= 0; '
                   f'{self.recenter_prior} is invalid.')
            raise ClassifierError(msg)


def check_stream(model: MiModel, channels: Sequence[str], rate: float) -> np.ndarray:
    """Check that a stream fits the model; returns the column indices of the model's channels."""
    if not np.isfinite(rate) or abs(rate - model.rate) > 1e-3 * model.rate:
        msg = (f'The stream runs at {rate} Hz but the model was trained at {model.rate} Hz; '
               'train a model at the stream rate (or resample the stream).')
        raise ClassifierError(msg)
    return channel_indices(channels, model.channels)


def check_classes(model: MiModel, expected: Sequence[int | str]) -> None:
    """Raise when the model's classes differ from the classes the application expects; a model
    may know ``rest`` besides them (rest is no command, every application can take it)."""
    from mindgrasp_classifier.model import class_index

    want = sorted(class_index(c) for c in expected)
    if want != sorted(c for c in model.classes if c != REST or REST in want):
        names = [DECODER_CLASS_NAMES[c] for c in want]
        msg = (f'The model decodes classes {model.class_names} but {names} are expected; '
               'train the model on those classes or change the expected classes.')
        raise ClassifierError(msg)


def filter_recording(model: MiModel, data: np.ndarray, channels: Sequence[str],
                     rate: float) -> np.ndarray:
    """Select the model's channels and band-pass a whole recording, causally.

    Parameters
    ----------
    data : ndarray, shape (n_samples, n_channels_recording)
        EEG in volts.

    Returns
    -------
    filtered : ndarray, shape (n_samples, n_channels_model)
        Filtered EEG in microvolts.
    """
    idx = check_stream(model, channels, rate)
    sos = design_bandpass(*model.band, model.rate, model.filter_order)
    x = np.asarray(data, dtype=float)[:, idx] * SCALE_V_TO_UV
    finite = np.isfinite(x).all(axis=1)
    if finite.all():
        return CausalBandpass(sos, len(idx)).process(x)
    # Lost samples (NaN rows): each finite segment is filtered from a fresh state, as the online
    # decoder restarts after a gap; NaN rows stay NaN and no window covers them.
    out = np.full_like(x, np.nan)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], finite.astype(int), [0]])))
    for start, stop in zip(edges[::2], edges[1::2], strict=True):
        out[start:stop] = CausalBandpass(sos, len(idx)).process(x[start:stop])
    return out


def window_covariances(model: MiModel, filtered: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Covariances of windows of ``filtered`` (:func:`filter_recording`) ending at ``ends``."""
    n_window = window_samples(model.rate, model.window)
    return model.covariances(extract_windows(filtered, ends, n_window))


def decode_windows(model: MiModel, covs: np.ndarray,
                   reference: np.ndarray | None = None) -> np.ndarray:
    """Per-class distances of covariances, re-centred on ``reference`` (training one by default).

    Returns
    -------
    distances : ndarray, shape (n_windows, n_classes)
    """
    ref = model.reference if reference is None else reference
    return model.classifier.distances(MiModel.recenter(covs, ref))


class MiDecoder:
    """Streaming decoder for one EEG stream.

    Parameters
    ----------
    model : MiModel
        Trained model; the decoder adapts a private copy.
    channels : sequence of str
        Channel names of the stream (the model's channels must be among them).
    rate : float
        Sampling rate of the stream (Hz); must equal the model's.
    adaptation : AdaptationConfig, optional
    flat_threshold : float
        A channel whose filtered standard deviation in a window is below this (volts) is flat.
    """

    def __init__(self, model: MiModel, channels: Sequence[str], rate: float,
                 adaptation: AdaptationConfig | None = None, flat_threshold: float = 1e-8) -> None:
        self.model = model.copy()
        self._idx = check_stream(self.model, channels, rate)
        self.adaptation = adaptation or AdaptationConfig()
        self.adaptation.check()
        if self.adaptation.mode != 'none' and not self.model.classifier.supports_mean_update:
            msg = (f'The {self.model.pipeline} pipeline has no class means to adapt; use an mdm '
                   'or fgmdm model, or set adaptation mode to none (re-centering still works).')
            raise ClassifierError(msg)
        self._classes = tuple(int(c) for c in self.model.classes)
        self.n_window = window_samples(self.model.rate, self.model.window)
        self.n_step = step_samples(self.model.rate, self.model.step)
        self._flat = flat_threshold * SCALE_V_TO_UV
        self._filter = CausalBandpass(
            design_bandpass(*self.model.band, self.model.rate, self.model.filter_order),
            len(self._idx))
        self._set_reference(np.array(self.model.reference, dtype=float))
        # the training reference counts as this many windows of the running mean
        self._n_ref_updates = round(self.adaptation.recenter_prior / self.model.step)
        self.label: int | None = None
        self.n_updates = 0
        self.reset()

    # --- state ---------------------------------------------------------------------------
    def reset(self) -> None:
        """Start a new segment: empty buffer and fresh filter state (after a gap or restart)."""
        self._filter.reset()
        self._buf = np.zeros((0, len(self._idx)))
        self._buf_start = 0          # stream index of _buf[0]
        self._next_index: int | None = None
        self._segment_start: int | None = None
        self._last_bad = -1          # stream index of the last non-finite sample
        self._bad_channels: list[str] = []

    @property
    def segment_start(self) -> int | None:
        """Stream index of the first sample of the current segment (filter start), or None.

        A replay that starts its decoder on the same sample reproduces every window exactly.
        """
        return self._segment_start

    @property
    def samples_buffered(self) -> int:
        """Samples of the current segment available for the next window (at most one window)."""
        if self._next_index is None or self._segment_start is None:
            return 0
        return min(self._next_index - self._segment_start, self.n_window)

    def set_label(self, class_index: int | None) -> None:
        """Current prompted class (supervised adaptation), ``None`` outside cue/move phases."""
        self.label = None if class_index is None else int(class_index)

    def recenter_to(self, covs: np.ndarray) -> None:
        """Set the re-centering reference from covariances of a calibration/rest block.

        ``covs`` shape (n_windows, n_channels, n_channels), from :meth:`MiModel.covariances`.
        """
        self._set_reference(riemann_mean(covs))
        self._n_ref_updates = len(covs)

    # --- streaming -----------------------------------------------------------------------
    def push(self, chunk: np.ndarray,
             first_sample_index: int | None = None) -> list[Prediction | Rejected]:
        """Feed one chunk; returns a result for every window that ended inside it.

        Parameters
        ----------
        chunk : ndarray, shape (n_samples, n_channels_stream)
            EEG in volts, channels in stream order.
        first_sample_index : int, optional
            Stream index of the chunk's first sample; a gap restarts the segment (filter and
            window buffer), an overlap drops the repeated samples.
        """
        chunk = np.asarray(chunk, dtype=float)
        if chunk.ndim != 2 or chunk.shape[1] < int(self._idx.max()) + 1:
            msg = (f'A chunk must have shape (n_samples, n_channels) with the stream\'s channels; '
                   f'got {chunk.shape}. Send samples as rows.')
            raise ClassifierError(msg)
        if first_sample_index is None:
            first_sample_index = self._next_index or 0
        first = int(first_sample_index)
        if self._next_index is not None and first < self._next_index:
            skip = self._next_index - first          # repeated samples: drop them
            chunk, first = chunk[skip:], self._next_index
        if self._next_index is not None and first > self._next_index:
            self.reset()                             # gap: restart the filter and the window
        if chunk.shape[0] == 0:
            return []
        if self._segment_start is None:
            self._segment_start = first
            self._buf_start = first
        x = chunk[:, self._idx] * SCALE_V_TO_UV
        bad = ~np.isfinite(x)
        if bad.any():
            # Hold the last finite value so the filter state stays finite; windows that contain
            # these samples are rejected.
            rows = np.nonzero(bad.any(axis=1))[0]
            self._last_bad = first + int(rows[-1])
            self._bad_channels = [self.model.channels[i] for i in np.nonzero(bad.any(axis=0))[0]]
            prev = self._buf[-1] if len(self._buf) else np.zeros(x.shape[1])
            for r in range(x.shape[0]):
                x[r] = np.where(np.isfinite(x[r]), x[r], prev)
                prev = x[r]
        y = self._filter.process(x)
        self._buf = np.concatenate([self._buf, y])
        self._next_index = first + chunk.shape[0]
        results: list[Prediction | Rejected] = []
        for end in _grid(max(self._segment_start + self.n_window - 1, first), self._next_index,
                         self.n_step):
            results.append(self._decode(end))
        keep = self.n_window - 1                      # samples needed for the next window
        if len(self._buf) > keep:
            drop = len(self._buf) - keep
            self._buf = self._buf[drop:]
            self._buf_start += drop
        return results

    def _decode(self, end: int) -> Prediction | Rejected:
        lo = end - self.n_window + 1 - self._buf_start
        window = self._buf[lo:lo + self.n_window]
        if end - self.n_window + 1 <= self._last_bad:
            return Rejected(end, f'Non-finite samples (NaN/Inf) in channels {self._bad_channels} '
                                 'within the last window; check the amplifier and electrodes.')
        std = window.std(axis=0)
        flat = [self.model.channels[i] for i in np.nonzero(std < self._flat)[0]]
        if flat:
            return Rejected(end, f'Flat channels {flat} (filtered std below '
                                 f'{self._flat / SCALE_V_TO_UV:g} V); check those electrodes.')
        cov = self.model.covariances(window.T[None])
        rec = self._ref_invsqrt @ cov @ self._ref_invsqrt
        d = self.model.classifier.distances(rec)[0]
        pos = int(np.argmin(d))
        cls = int(self.model.classes[pos])
        pred = Prediction(class_index=cls, certainty=float(certainty_of(d)), sample_index=end,
                          distances=d, probabilities=self.model.probabilities(d),
                          classes=self._classes)
        self._adapt(cov[0], rec[0], pred, pos)
        return pred

    def _adapt(self, cov: np.ndarray, rec: np.ndarray, pred: Prediction, pos: int) -> None:
        cfg = self.adaptation
        if cfg.mode != 'none':
            target = None
            if self.label is not None and cfg.mode in ('supervised', 'both'):
                if self.label in self.model.classes:
                    target = self.model.classes.index(self.label)
            elif (self.label is None and cfg.mode in ('unsupervised', 'both')
                  and pred.certainty >= cfg.min_certainty):
                target = pos
            if target is not None and cfg.rate > 0:
                self.model.classifier.update_mean(target, rec, cfg.rate)
                self.n_updates += 1
        if cfg.recenter == 'adaptive':
            self._n_ref_updates += 1
            w = max(1.0 / self._n_ref_updates, cfg.recenter_rate)
            # the affine-invariant geodesic A^1/2 (A^-1/2 B A^-1/2)^w A^1/2, as pyriemann's
            # geodesic_riemann computes it, but with A's square roots from the one
            # eigendecomposition already made for the re-centering (2 eigh per window, not 4)
            inner = _spd_function(self._ref_invsqrt @ cov @ self._ref_invsqrt, lambda x: x ** w)
            self._set_reference(self._ref_sqrt @ inner @ self._ref_sqrt)

    def _set_reference(self, reference: np.ndarray) -> None:
        """The re-centering reference (n_channels, n_channels) and its square roots."""
        self.reference = reference
        vals, vecs = np.linalg.eigh(reference)
        self._ref_sqrt = _from_eigen(vals, vecs, np.sqrt(vals))
        self._ref_invsqrt = _from_eigen(vals, vecs, 1.0 / np.sqrt(vals))


def _from_eigen(vals: np.ndarray, vecs: np.ndarray, f_vals: np.ndarray) -> np.ndarray:
    """``V diag(f(vals)) V^T``, the product pyriemann's matrix functions form (same order of
    operations, so the same bits)."""
    return vecs @ (f_vals[..., None] * vecs.T)


def _spd_function(matrix: np.ndarray, f) -> np.ndarray:
    """A matrix function of a symmetric positive-definite matrix (n, n), via eigh."""
    if not np.isfinite(matrix).all():
        msg = 'Re-centering met a non-finite covariance; check the amplifier and electrodes.'
        raise ClassifierError(msg)
    vals, vecs = np.linalg.eigh(matrix)
    return _from_eigen(vals, vecs, f(vals))


def _grid(first: int, stop: int, n_step: int) -> range:
    """Window ends in [first, stop) on the global grid (end + 1) % n_step == 0."""
    first += (-(first + 1)) % n_step
    return range(first, stop, n_step)


class CueLabels:
    """Labels for supervised adaptation from timed cues (trainer prompts).

    A window is labelled with a cue's class when it lies inside ``[onset + tmin, onset + tmax]``
    (the training epoch), so online updates use the same part of a trial as training did.

    Parameters
    ----------
    tmin, tmax : float
        Labelled interval after each cue onset (s).
    """

    def __init__(self, tmin: float = 0.5, tmax: float = 2.5) -> None:
        self.tmin, self.tmax = tmin, tmax
        self._cues: list[tuple[float, int]] = []

    def add(self, onset: float, class_index: int) -> None:
        """A cue of ``class_index`` at ``onset`` (s, any clock shared with the windows)."""
        self._cues.append((float(onset), int(class_index)))
        self._cues = self._cues[-8:]   # only recent cues matter

    def label(self, start: float, end: float) -> int | None:
        """Class of the window ``[start, end]`` (s), or ``None`` if it is outside every epoch."""
        for onset, cls in reversed(self._cues):
            if start >= onset + self.tmin - 1e-9 and end <= onset + self.tmax + 1e-9:
                return cls
        return None
