"""SosStream against scipy.signal.sosfilt: the same output and state, to the last bit; only
SciPy's public API (no ``scipy.signal._sosfilt``)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from mindgrasp_common.sos_stream import SosStream


def test_chunk_by_chunk_equals_sosfilt() -> None:
    sos = signal.butter(4, [8.0, 30.0], 'bandpass', fs=250.0, output='sos')
    rng = np.random.default_rng(3)
    zi0 = rng.standard_normal((sos.shape[0], 2, 5))
    stream = SosStream(sos, 5, zi=zi0)
    zi = zi0
    for n in (1, 7, 16, 33):
        x = rng.standard_normal((n, 5))
        expected, zi = signal.sosfilt(sos, x, axis=0, zi=zi)
        got = stream(x)
        assert got.shape == (n, 5)
        assert np.array_equal(got, expected)
        assert np.array_equal(stream.state, zi)


def test_bad_shapes_are_named() -> None:
    sos = signal.butter(2, 10.0, fs=250.0, output='sos')
    with pytest.raises(ValueError, match=r'\(n_sections, 6\)'):
        SosStream(sos[:, :5], 3)
    stream = SosStream(sos, 3)
    with pytest.raises(ValueError, match=r'\(n_samples, 3\)'):
        stream(np.zeros((4, 2)))
    with pytest.raises(ValueError, match='state must have shape'):
        stream.set_state(np.zeros((2, 2, 3)))


def test_only_scipys_public_api() -> None:
    from pathlib import Path

    import mindgrasp_common.sos_stream as module

    assert '_sosfilt' not in Path(module.__file__).read_text(encoding='utf-8')
