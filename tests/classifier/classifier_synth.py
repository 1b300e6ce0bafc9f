"""Seeded synthetic recordings with known class covariances for the classifier tests."""

from __future__ import annotations

import numpy as np

from mindgrasp_classifier.data import Recording

CHANNELS = ['FC3', 'FC4', 'C5', 'C3', 'C1', 'Cz', 'C2', 'C4', 'C6', 'CP3', 'CPz', 'CP4']
RATE = 128.0


def class_mixings(n_channels: int, classes, seed: int = 1234) -> dict[int, np.ndarray]:
    """A distinct, well-conditioned mixing matrix per class (class covariance = M M^T)."""
    rng = np.random.RandomState(seed)
    out = {}
    for c in classes:
        q, _ = np.linalg.qr(rng.randn(n_channels, n_channels))
        out[int(c)] = q @ np.diag(np.exp(rng.uniform(-1.0, 1.0, n_channels)))
    return out


def make_recording(classes=(0, 1, 2, 3), trials_per_class: int = 10, seed: int = 0,
                   rate: float = RATE, channels=CHANNELS, drift: np.ndarray | None = None,
                   mixing_seed: int = 1234, amplitude: float = 10e-6,
                   annotate: bool = False, source: str | None = None) -> Recording:
    """Continuous EEG (V): rest = white noise, each cue 3 s of class-mixed noise, 2 s rest.

    ``annotate`` adds EEGMMIDB-like annotations (s): ``C<class>`` over each 3 s cue and ``T0``
    (rest) over the 3 s from each cue's end to the next cue (2 s at the end)."""
    rng = np.random.RandomState(seed)
    n_ch = len(channels)
    mix = class_mixings(n_ch, classes, mixing_seed)
    order = rng.permutation(np.repeat(np.asarray(classes), trials_per_class))
    pre, cue, rest = round(1.0 * rate), round(3.0 * rate), round(2.0 * rate)
    blocks, events, t, annotations = [], [], 0, []
    for i, cls in enumerate(order):
        blocks.append(rng.randn(pre, n_ch))
        events.append((t + pre, int(cls)))
        blocks.append(rng.randn(cue, n_ch) @ mix[int(cls)].T)
        blocks.append(rng.randn(rest, n_ch))
        annotations += [((t + pre) / rate, cue / rate, f'C{int(cls)}'),
                        ((t + pre + cue) / rate, (rest + (pre if i + 1 < len(order) else 0)) / rate,
                         'T0')]
        t += pre + cue + rest
    data = np.concatenate(blocks) * amplitude + 20e-6   # DC offset as real amplifiers have
    if drift is not None:
        data = data @ drift.T
    return Recording(data=data, rate=rate, channels=list(channels),
                     events=np.array(events, dtype=int), source=source or f'synthetic seed {seed}',
                     annotations=annotations if annotate else [])
