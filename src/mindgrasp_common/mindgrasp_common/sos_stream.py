"""A second-order-sections filter applied chunk by chunk (EEG synthesis, online band-pass).

:class:`SosStream` keeps a filter's state from one chunk to the next and calls SciPy's public
``scipy.signal.sosfilt(sos, x, axis=0, zi=zi)``, with the state kept in that function's layout so
nothing is copied between calls: the output is sosfilt's, to the last bit (a test checks it).
"""

from __future__ import annotations

import numpy as np
from scipy import signal

__all__ = ['SosStream']


class SosStream:
    """Causal SOS filter along the time axis of ``(n_samples, n_signals)`` chunks, its state
    carried from one chunk to the next.

    Parameters
    ----------
    sos : array_like, shape (n_sections, 6)
        Second-order sections (``scipy.signal`` format).
    n_signals : int
        Number of signals (columns) of every chunk.
    zi : array_like, shape (n_sections, 2, n_signals), optional
        Initial state in ``sosfilt(..., axis=0)``'s layout; zeros (rest) by default.
    """

    def __init__(self, sos: np.ndarray, n_signals: int, zi: np.ndarray | None = None) -> None:
        sos = np.asarray(sos, dtype=float)
        if sos.ndim != 2 or sos.shape[1] != 6 or not np.all(sos[:, 3] == 1):
            msg = f'sos must have shape (n_sections, 6) with sos[:, 3] == 1; got {sos.shape}.'
            raise ValueError(msg)
        self.sos = np.ascontiguousarray(sos)
        self.n_signals = int(n_signals)
        self.set_state(np.zeros((sos.shape[0], 2, self.n_signals)) if zi is None else zi)

    @property
    def state(self) -> np.ndarray:
        """The filter state (n_sections, 2, n_signals), as ``sosfilt(..., axis=0)`` returns it."""
        return self._zi.copy()

    def set_state(self, zi: np.ndarray) -> None:
        """Replace the state with ``zi`` (n_sections, 2, n_signals)."""
        zi = np.array(zi, dtype=float)
        shape = (self.sos.shape[0], 2, self.n_signals)
        if zi.shape != shape:
            msg = f'The filter state must have shape {shape}; got {zi.shape}.'
            raise ValueError(msg)
        self._zi = zi

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """Filter the next chunk ``x`` (n_samples, n_signals); returns the output, same shape
        (a new float64 array; ``x`` is not modified)."""
        if x.ndim != 2 or x.shape[1] != self.n_signals:
            msg = f'Chunks must have shape (n_samples, {self.n_signals}); got {x.shape}.'
            raise ValueError(msg)
        y, self._zi = signal.sosfilt(self.sos, x, axis=0, zi=self._zi)
        return y
