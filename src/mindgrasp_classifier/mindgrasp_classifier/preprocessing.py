"""Causal band-pass filtering, channel selection and sliding windows.

The same objects run offline (training, evaluation) and online (the classifier node), so a model
sees exactly the preprocessing it was trained with.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy import signal

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_common.sos_stream import SosStream

#: Motor strip (10-10 names): the default channel selection.
MOTOR_STRIP: tuple[str, ...] = (
    'FC5', 'FC3', 'FC1', 'FCz', 'FC2', 'FC4', 'FC6',
    'C5', 'C3', 'C1', 'Cz', 'C2', 'C4', 'C6',
    'CP5', 'CP3', 'CP1', 'CPz', 'CP2', 'CP4', 'CP6',
    'T7', 'T8',
)
#: Fewer motor channels than this in a montage: ask the user to choose channels explicitly.
MIN_MOTOR_CHANNELS = 3


def select_channels(available: Sequence[str],
                    selection: str | Sequence[str] = 'motor') -> list[str]:
    """Names of the channels to decode, in the order of ``available``.

    Parameters
    ----------
    available : sequence of str
        Channel names of the recording or stream (10-20/10-10 names; matched case-insensitively).
    selection : 'motor' | 'all' | sequence of str
        ``'motor'`` keeps the motor strip (:data:`MOTOR_STRIP`), ``'all'`` keeps every channel,
        a list keeps exactly those channels.

    Returns
    -------
    names : list of str
        Selected names, spelled as in ``available``.
    """
    lower = {name.lower(): name for name in available}
    if isinstance(selection, str):
        key = selection.lower()
        if key == 'all':
            return list(available)
        if key != 'motor':
            selection = [s.strip() for s in selection.split(',') if s.strip()]
        else:
            wanted = {n.lower() for n in MOTOR_STRIP}
            chosen = [name for name in available if name.lower() in wanted]
            if len(chosen) < MIN_MOTOR_CHANNELS:
                msg = (f'Only {len(chosen)} motor-strip channels ({chosen}) are in the montage '
                       f'{list(available)}; choose channels explicitly (e.g. channels: all, or a '
                       'list of names).')
                raise ClassifierError(msg)
            return chosen
    missing = [name for name in selection if name.lower() not in lower]
    if missing:
        msg = (f'The channels {missing} are not in the recording, which has {list(available)}; '
               'choose channels that exist (or use all).')
        raise ClassifierError(msg)
    if len(set(n.lower() for n in selection)) != len(selection):
        msg = f'The channel list {list(selection)} names a channel twice; list each channel once.'
        raise ClassifierError(msg)
    return [lower[name.lower()] for name in selection]


def channel_indices(available: Sequence[str], names: Sequence[str]) -> np.ndarray:
    """Column indices of ``names`` in ``available`` (case-insensitive); raises if one is missing."""
    lower = [a.lower() for a in available]
    missing = [n for n in names if n.lower() not in lower]
    if missing:
        msg = (f'The model needs the channels {missing}, which the stream {list(available)} does '
               'not have; use a model trained on this montage or fix the channel names.')
        raise ClassifierError(msg)
    return np.array([lower.index(n.lower()) for n in names], dtype=int)


def design_bandpass(low: float, high: float, rate: float, order: int = 4) -> np.ndarray:
    """Butterworth band-pass in second-order sections.

    Parameters
    ----------
    low, high : float
        Pass band edges (Hz), ``0 < low < high < rate / 2``.
    rate : float
        Sampling rate (Hz).
    order : int
        Butterworth order (the band-pass has ``2 * order`` poles).

    Returns
    -------
    sos : ndarray, shape (n_sections, 6)
    """
    if not 0 < low < high < rate / 2:
        msg = (f'The band-pass {low}-{high} Hz does not fit a sampling rate of {rate} Hz; choose '
               f'edges with 0 < low < high < {rate / 2} Hz.')
        raise ClassifierError(msg)
    if order < 1:
        msg = f'The filter order must be at least 1; {order} is invalid.'
        raise ClassifierError(msg)
    return signal.butter(order, [low, high], btype='bandpass', fs=rate, output='sos')


class CausalBandpass:
    """Causal SOS band-pass whose state carries across chunks.

    Filtering a recording in one call or chunk by chunk gives the same output (to rounding), so
    online and offline windows match. The initial state is the filter's step-response steady
    state for the first sample, which avoids a large transient from the DC offset.

    Parameters
    ----------
    sos : ndarray, shape (n_sections, 6)
        Filter from :func:`design_bandpass`.
    n_channels : int
        Number of channels (columns) of the data.
    """

    def __init__(self, sos: np.ndarray, n_channels: int) -> None:
        self.sos = np.asarray(sos, dtype=float)
        self.n_channels = int(n_channels)
        self._zi_unit = signal.sosfilt_zi(self.sos)  # (n_sections, 2)
        self._stream: SosStream | None = None

    def reset(self) -> None:
        """Forget the filter state (next chunk starts a new segment)."""
        self._stream = None

    def process(self, chunk: np.ndarray) -> np.ndarray:
        """Filter one chunk.

        Parameters
        ----------
        chunk : ndarray, shape (n_samples, n_channels)
            Consecutive samples (any unit; output has the same unit).

        Returns
        -------
        out : ndarray, shape (n_samples, n_channels)
        """
        chunk = np.asarray(chunk, dtype=float)
        if chunk.ndim != 2 or chunk.shape[1] != self.n_channels:
            msg = (f'The filter expects chunks of shape (n_samples, {self.n_channels}); got '
                   f'{chunk.shape}. Pass samples as rows and channels as columns.')
            raise ClassifierError(msg)
        if chunk.shape[0] == 0:
            return chunk.copy()
        if self._stream is None:
            self._stream = SosStream(self.sos, self.n_channels,
                                     zi=self._zi_unit[:, :, None] * chunk[0][None, None, :])
        return self._stream(chunk)


def step_samples(rate: float, step: float) -> int:
    """Window step in samples (at least 1) for a step of ``step`` seconds.

    Rounded down, so the prediction rate is never below ``1 / step`` (250 Hz, 1/16 s: 15
    samples, 16.7 predictions/s).
    """
    return max(1, int(rate * step + 1e-9))


def window_samples(rate: float, length: float) -> int:
    """Window length in samples for ``length`` seconds; must cover at least 2 samples."""
    n = round(rate * length)
    if n < 2:
        msg = f'A window of {length} s at {rate} Hz has {n} samples; use a window of >= 2 samples.'
        raise ClassifierError(msg)
    return n


def window_ends(start: int, stop: int, n_window: int, n_step: int) -> np.ndarray:
    """Last-sample indices of the windows that lie inside ``[start, stop)``.

    Windows end on the global grid ``(end + 1) % n_step == 0`` (sample indices counted from the
    start of the recording/stream), the same grid the online decoder uses, so offline and online
    windows coincide.

    Returns
    -------
    ends : ndarray of int, shape (n_windows,)
        Inclusive last-sample index of each window; the window is ``[end - n_window + 1, end]``.
    """
    first = start + n_window - 1
    first += (-(first + 1)) % n_step
    if first >= stop:
        return np.zeros(0, dtype=int)
    return np.arange(first, stop, n_step, dtype=int)


def extract_windows(data: np.ndarray, ends: np.ndarray, n_window: int) -> np.ndarray:
    """Windows of ``data`` ending at ``ends``.

    Parameters
    ----------
    data : ndarray, shape (n_samples, n_channels)
    ends : ndarray of int, shape (n_windows,)
    n_window : int

    Returns
    -------
    X : ndarray, shape (n_windows, n_channels, n_window)
    """
    idx = np.asarray(ends)[:, None] + np.arange(-n_window + 1, 1)[None, :]
    return np.ascontiguousarray(np.transpose(data[idx], (0, 2, 1)))


def oas_covariances(windows: np.ndarray) -> np.ndarray:
    """Oracle Approximating Shrinkage covariances of many windows at once.

    The same estimate as pyRiemann ``Covariances(estimator='oas')`` (scikit-learn's ``oas`` per
    window, data centred), vectorised over windows so one online prediction stays well under a
    millisecond; ``tests/classifier`` checks the equality.

    Parameters
    ----------
    windows : ndarray, shape (n_windows, n_channels, n_samples)

    Returns
    -------
    covs : ndarray, shape (n_windows, n_channels, n_channels)
    """
    x = np.asarray(windows, dtype=float)
    _, n_ch, n_t = x.shape
    x = x - x.mean(axis=2, keepdims=True)
    emp = x @ x.transpose(0, 2, 1) / n_t
    if n_ch == 1:
        return emp
    mu = np.trace(emp, axis1=1, axis2=2) / n_ch                 # (n_win,)
    alpha = np.mean(emp ** 2, axis=(1, 2))
    num = alpha + mu ** 2
    den = (n_t + 1) * (alpha - mu ** 2 / n_ch)
    with np.errstate(divide='ignore', invalid='ignore'):
        shrink = np.where(den == 0, 1.0, np.minimum(num / np.where(den == 0, 1.0, den), 1.0))
    covs = (1.0 - shrink)[:, None, None] * emp
    idx = np.arange(n_ch)
    covs[:, idx, idx] += (shrink * mu)[:, None]
    return covs
