"""Signal quality of a multichannel EEG stream: NaN/inf, flat and railed channels (ROS-free)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class QualityMonitor:
    """Flags bad channels over a sliding window.

    Parameters
    ----------
    channel_names : sequence of str, length n_channels
    sample_rate : float
        Hz.
    window : float
        Length of the sliding window (s).
    flat_threshold : float
        A channel whose standard deviation over a full window is below this (V) is flat.
    rail_threshold : float
        A channel with more than 10 % of the window at or beyond +/- this value (V) is railed
        (amplifier saturation or electrode off).

    Attributes
    ----------
    nonfinite_samples : ndarray of int, shape (n_channels,)
        NaN/inf values seen per channel since the start.
    """

    def __init__(self, channel_names: Sequence[str], sample_rate: float, *, window: float = 1.0,
                 flat_threshold: float = 1e-7, rail_threshold: float = 0.1) -> None:
        self.channel_names = tuple(channel_names)
        n_ch = len(self.channel_names)
        self._size = max(2, round(window * sample_rate))
        self._buf = np.zeros((self._size, n_ch))
        self._filled = 0
        self._pos = 0
        self.flat_threshold, self.rail_threshold = flat_threshold, rail_threshold
        self.nonfinite_samples = np.zeros(n_ch, dtype=np.int64)
        self._since_nonfinite = np.full(n_ch, np.iinfo(np.int64).max // 2, dtype=np.int64)

    def update(self, data: np.ndarray) -> None:
        """Add samples, shape (n_samples, n_channels), in volts (may contain NaN/inf)."""
        bad = ~np.isfinite(data)
        n = len(data)
        self.nonfinite_samples += bad.sum(axis=0)
        last_bad = np.where(bad.any(axis=0), n - 1 - np.argmax(bad[::-1], axis=0), -1)
        self._since_nonfinite = np.where(last_bad >= 0, n - 1 - last_bad,
                                         self._since_nonfinite + n)
        clean = np.where(bad, 0.0, data)[-self._size:]
        k = len(clean)
        idx = (self._pos + np.arange(k)) % self._size
        self._buf[idx] = clean
        self._pos = (self._pos + k) % self._size
        self._filled = min(self._size, self._filled + k)

    def _names(self, mask: np.ndarray) -> list[str]:
        return [c for c, m in zip(self.channel_names, mask, strict=True) if m]

    def nonfinite_channels(self) -> list[str]:
        """Channels with NaN/inf within the last window."""
        return self._names(self._since_nonfinite < self._size)

    def flat_channels(self) -> list[str]:
        """Channels whose standard deviation over the last (full) window is below the threshold."""
        if self._filled < self._size:
            return []
        return self._names(self._buf.std(axis=0) < self.flat_threshold)

    def railed_channels(self) -> list[str]:
        """Channels at or beyond the rail in more than 10 % of the last window."""
        window = self._buf[:self._filled]
        if not len(window):
            return []
        return self._names(np.mean(np.abs(window) >= self.rail_threshold, axis=0) > 0.1)
