"""XDF files (pyxdf reader) in the dataset player: an XDF written here byte by byte per the spec."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.player import load_recording
from mindgrasp_testing import write_xdf


def test_xdf_recording_in_volts_with_markers(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    eeg = rng.normal(0, 20, (300, 3)).astype(np.float32)          # microvolts
    path = tmp_path / 'session.xdf'
    write_xdf(path, eeg, 100.0, 5000.0, [(5000.5, 'cue/left_hand'), (5002.0, 'rest')],
              ['C3', 'Cz', 'C4'])
    rec = load_recording(path)
    assert rec.rate == 100.0 and rec.channels == ['C3', 'Cz', 'C4']
    np.testing.assert_allclose(rec.data, eeg * 1e-6, rtol=1e-6)
    assert [d for _o, _dur, d in rec.annotations] == ['cue/left_hand', 'rest']
    assert rec.annotations[0][0] == pytest.approx(0.5, abs=1e-3)
    assert rec.annotations[1][0] == pytest.approx(2.0, abs=1e-3)


def test_xdf_without_eeg_and_corrupt(tmp_path: Path) -> None:
    path = tmp_path / 'broken.xdf'
    path.write_bytes(b'XDF:' + b'\x04garbage' * 4)
    with pytest.raises(EEGError, match='holds no regularly sampled stream; record the EEG'):
        load_recording(path)                  # pyxdf skips what it cannot parse
    path.write_bytes(b'not an xdf file at all')
    with pytest.raises(EEGError, match=r'Cannot read the EEG file .*corrupt'):
        load_recording(path)
