"""XDF files (pyxdf reader) in the dataset player: an XDF written here byte by byte per the spec."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.player import load_recording


def _chunk(tag: int, content: bytes) -> bytes:
    body = struct.pack('<H', tag) + content
    return struct.pack('<BI', 4, len(body)) + body


def _varlen(n: int) -> bytes:
    return struct.pack('<BI', 4, n)


def write_xdf(path: Path, eeg_uv: np.ndarray, fs: float, t0: float,
              markers: list[tuple[float, str]], names: list[str], unit: str = 'microvolts') -> None:
    """XDF 1.0: file header, an EEG stream (float32) and a string marker stream."""
    chans = ''.join(f'<channel><label>{n}</label><unit>{unit}</unit><type>EEG</type></channel>'
                    for n in names)
    eeg_hdr = (f'<?xml version="1.0"?><info><name>amp</name><type>EEG</type>'
               f'<channel_count>{len(names)}</channel_count><nominal_srate>{fs}</nominal_srate>'
               f'<channel_format>float32</channel_format><created_at>0</created_at>'
               f'<desc><channels>{chans}</channels></desc></info>')
    mk_hdr = ('<?xml version="1.0"?><info><name>amp-markers</name><type>Markers</type>'
              '<channel_count>1</channel_count><nominal_srate>0</nominal_srate>'
              '<channel_format>string</channel_format><created_at>0</created_at></info>')
    out = b'XDF:' + _chunk(1, b'<?xml version="1.0"?><info><version>1.0</version></info>')
    out += _chunk(2, struct.pack('<I', 1) + eeg_hdr.encode())
    out += _chunk(2, struct.pack('<I', 2) + mk_hdr.encode())
    samples = b''.join(struct.pack('<Bd', 8, t0 + k / fs) + row.astype('<f4').tobytes()
                       for k, row in enumerate(eeg_uv))
    out += _chunk(3, struct.pack('<I', 1) + _varlen(len(eeg_uv)) + samples)
    mk = b''.join(struct.pack('<Bd', 8, t) + _varlen(len(s)) + s.encode() for t, s in markers)
    out += _chunk(3, struct.pack('<I', 2) + _varlen(len(markers)) + mk)
    for sid, first, last, n in ((1, t0, t0 + (len(eeg_uv) - 1) / fs, len(eeg_uv)),
                                (2, markers[0][0], markers[-1][0], len(markers))):
        footer = (f'<?xml version="1.0"?><info><first_timestamp>{first}</first_timestamp>'
                  f'<last_timestamp>{last}</last_timestamp><sample_count>{n}</sample_count>'
                  f'</info>')
        out += _chunk(6, struct.pack('<I', sid) + footer.encode())
    path.write_bytes(out)


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
