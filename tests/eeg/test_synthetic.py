"""Synthetic EEG: shapes, units, seeds, class-conditional band power, artefacts."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import NAUTILUS_32
from mindgrasp_eeg.synthetic import SyntheticEEG

FS = 250.0


def band_power(x: np.ndarray, ch: str, lo: float = 8.0, hi: float = 26.0) -> float:
    f, p = signal.welch(x[:, NAUTILUS_32.index(ch)], FS, nperseg=250)
    return float(p[(f >= lo) & (f <= hi)].sum())


def test_shape_units_and_seed() -> None:
    a = SyntheticEEG(seed=3).generate(500, None)
    b = SyntheticEEG(seed=3)
    b_data = np.vstack([b.generate(123, None), b.generate(377, None)])
    assert a.shape == (500, 32)
    np.testing.assert_allclose(a, b_data)                    # chunking does not change the signal
    assert 5e-6 < a.std() < 50e-6                            # tens of microvolts, in volts
    assert not np.allclose(a, SyntheticEEG(seed=4).generate(500, None))


@pytest.mark.parametrize(('mi_class', 'down', 'same'), [
    (0, ['C4'], ['C3', 'Cz']),          # left hand: right motor cortex
    (1, ['C3'], ['C4', 'Cz']),          # right hand: left motor cortex
    (2, ['C3', 'C4'], ['Cz']),          # both hands
    (3, ['Cz'], ['C3', 'C4']),          # feet: vertex
])
def test_class_conditional_band_power(mi_class: int, down: list[str], same: list[str]) -> None:
    rest = SyntheticEEG(seed=11).generate(int(40 * FS), None)
    mi = SyntheticEEG(seed=11).generate(int(40 * FS), mi_class)
    for ch in down:
        assert band_power(mi, ch) < 0.6 * band_power(rest, ch), ch
    for ch in same:
        assert band_power(mi, ch) == pytest.approx(band_power(rest, ch), rel=0.15), ch
    # alpha over the occipital cortex is not motor imagery
    assert band_power(mi, 'Oz') == pytest.approx(band_power(rest, 'Oz'), rel=0.1)


def test_background_is_one_over_f() -> None:
    x = SyntheticEEG(seed=2, alpha_rms=0, mu_rms=0, beta_rms=0).generate(int(60 * FS))
    f, p = signal.welch(x[:, NAUTILUS_32.index('Pz')], FS, nperseg=500)
    slope = np.polyfit(np.log(f[(f > 2) & (f < 60)]), np.log(p[(f > 2) & (f < 60)]), 1)[0]
    assert -1.5 < slope < -0.6


def test_artefacts_are_optional_and_located() -> None:
    clean = SyntheticEEG(seed=5).generate(int(20 * FS))
    blinks = SyntheticEEG(seed=5, blink_rate=0.5).generate(int(20 * FS))
    fp1, oz = NAUTILUS_32.index('Fp1'), NAUTILUS_32.index('Oz')
    assert np.abs(blinks[:, fp1]).max() > 60e-6 > np.abs(clean[:, fp1]).max()
    assert np.abs(blinks[:, oz] - clean[:, oz]).max() < 5e-6
    emg = SyntheticEEG(seed=5, emg_rate=0.5).generate(int(20 * FS))
    hf = NAUTILUS_32.index('T7'), NAUTILUS_32.index('T8')
    assert max(band_power(emg, NAUTILUS_32[i], 60, 120) for i in hf) > \
        3 * max(band_power(clean, NAUTILUS_32[i], 60, 120) for i in hf)


def test_bad_parameters() -> None:
    with pytest.raises(EEGError, match='no position for channels'):
        SyntheticEEG(channel_names=['C3', 'XYZ'])
    with pytest.raises(EEGError, match='at least 60 Hz'):
        SyntheticEEG(sample_rate=50)
    with pytest.raises(EEGError, match='not a motor-imagery class'):
        SyntheticEEG().generate(10, 7)
