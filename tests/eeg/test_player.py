"""Dataset player: EEGMMIDB S001 over LSL (real player process), rate, marker alignment, errors."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pylsl
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.player import expand_sources, load_recording

FS = 160.0


def eegbci_file(run: int) -> str:
    """S001 run file via MNE's loader, from the local copy only (tests never download)."""
    root = os.environ.get('MNE_DATASETS_EEGBCI_PATH')
    local = (Path(root) / 'MNE-eegbci-data/files/eegmmidb/1.0.0/S001' / f'S001R{run:02d}.edf'
             if root else None)
    if local is None or not local.is_file():
        pytest.skip(f'EEGMMIDB S001 is not available here ({local}); set '
                    f'MNE_DATASETS_EEGBCI_PATH to the shared data folder.')
    return expand_sources([f'eegbci:1:{run}'])[0]


def start_player(name: str, *args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'eeg', 'play', *args,
                             '--name', name], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)


def open_inlet(name: str) -> pylsl.StreamInlet:
    found = pylsl.resolve_byprop('name', name, timeout=60)   # a busy host starts it slowly
    assert found, f'stream {name} not found'
    inlet = pylsl.StreamInlet(found[0], processing_flags=pylsl.proc_clocksync)
    inlet.open_stream(timeout=30)
    return inlet


@pytest.mark.slow
def test_eegmmidb_playback_rate_and_marker_alignment(stream_name) -> None:
    path = eegbci_file(4)
    rec = load_recording(path)
    player = start_player(stream_name, path, '--duration', '12')
    try:
        eeg, markers = open_inlet(stream_name), open_inlet(stream_name + '-markers')
        info = eeg.info()
        assert info.channel_count() == 64 and info.nominal_srate() == FS
        data, ts, arrival, mk = [], [], [], []
        t_end = time.monotonic() + 6.5
        while time.monotonic() < t_end:
            d, t = eeg.pull_chunk(timeout=0.0, max_samples=1024, as_numpy=True)
            if len(t):
                data.append(d)
                ts.append(t)
                arrival.append(pylsl.local_clock() - t[-1])    # how late its last sample is
            m, mt = markers.pull_chunk(timeout=0.0)
            mk += [(row[0], stamp) for row, stamp in zip(m, mt, strict=True)]
            time.sleep(0.01)
    finally:
        player.kill()
        player.wait()
    data, ts = np.vstack(data) * 1e-6, np.concatenate(ts)
    # the samples are the file's, in order: locate the first one in the file
    k0 = int(np.argmin(np.abs(rec.data[:2000] - data[0]).sum(axis=1)))
    np.testing.assert_allclose(data, rec.data[k0:k0 + len(data)], atol=1e-9)
    # real time: samples stamped 1 / FS apart arrive when their time has come, never before,
    # and not later and later (a pace below FS); medians, so a stall of this reader (a loaded
    # host) does not count as the player's
    np.testing.assert_allclose(np.diff(ts), 1 / FS, atol=1e-4)
    lag = np.array(arrival)
    assert lag.min() > -0.005, lag.min()
    quarter = max(1, len(lag) // 4)
    assert abs(np.median(lag[-quarter:]) - np.median(lag[:quarter])) < 0.05, lag
    # markers: each one within 10 ms of the timestamp of its annotation's sample
    assert mk, 'no marker arrived'
    onsets = {round(o * FS): desc for o, _d, desc in rec.annotations}
    checked = 0
    for desc, stamp in mk:
        k = round((stamp - ts[0]) * FS) + k0          # nearest sample
        assert onsets.get(k) == desc, (desc, k)
        i = k - k0
        if 0 <= i < len(ts):
            assert abs(ts[i] - stamp) < 0.010
            checked += 1
    assert checked >= 1


@pytest.mark.slow
def test_rate_and_loop(tmp_path, stream_name) -> None:
    import mne

    sfreq, n = 100.0, 300                               # a 3 s recording with two annotations
    info = mne.create_info(['C3', 'Cz', 'C4'], sfreq, 'eeg')
    raw = mne.io.RawArray(np.arange(n * 3, dtype=float).reshape(3, n) * 1e-7, info,
                          verbose='error')
    raw.set_annotations(mne.Annotations([0.5, 2.0], [1.0, 1.0], ['left_hand', 'rest']))
    path = tmp_path / 'tiny_raw.fif'
    raw.save(path, verbose='error')
    player = start_player(stream_name, str(path), '--rate', '4', '--loop', '--duration', '60')
    values, stamps, late, mk = [], [], [], []
    try:
        eeg, markers = open_inlet(stream_name), open_inlet(stream_name + '-markers')
        deadline = time.monotonic() + 60.0          # 4 loops take 3 s; a busy host takes longer
        while time.monotonic() < deadline and len(values) < 4 * n:
            d, t = eeg.pull_chunk(timeout=0.0, max_samples=1024)
            if t:
                # a sample is pushed when its time has come, never before
                late.append(pylsl.local_clock() - t[-1])
                values += [row[0] for row in d]
                stamps += t
            m, _mt = markers.pull_chunk(timeout=0.0)
            mk += [row[0] for row in m]
            time.sleep(0.01)
    finally:
        player.kill()
        player.wait()
    assert len(values) >= 4 * n, len(values)
    # 4x real time: samples 1 / (4 * sfreq) apart on the stream clock, none pushed ahead of it
    # (to within the inlet's clock-offset updates, microseconds)
    np.testing.assert_allclose(np.diff(stamps), 1 / (4 * sfreq), atol=1e-4)
    assert min(late) > -0.005, min(late)
    # looped: the first channel's ramp starts again at 0 every n samples
    assert int((np.diff(values) < 0).sum()) >= 3
    assert mk.count('left_hand') >= 3 and mk.count('rest') >= 3


def test_corrupt_and_unsupported_files(tmp_path) -> None:
    bad = tmp_path / 'broken.edf'
    bad.write_bytes(b'0       not an EDF header at all' * 3)
    with pytest.raises(EEGError, match=r'Cannot read the EEG file .*broken\.edf.*corrupt'):
        load_recording(bad)
    with pytest.raises(EEGError, match=r"unsupported format '\.txt'"):
        (tmp_path / 'x.txt').write_text('1 2 3')
        load_recording(tmp_path / 'x.txt')
    with pytest.raises(EEGError, match='does not exist'):
        load_recording(tmp_path / 'missing.gdf')
    with pytest.raises(EEGError, match='is not an EEGMMIDB reference'):
        expand_sources(['eegbci:one:4'])


def test_cli_reports_bad_file(tmp_path) -> None:
    bad = tmp_path / 'broken.fif'
    bad.write_bytes(b'\x00' * 100)
    proc = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'eeg', 'play', str(bad)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 1
    assert 'Cannot read the EEG file' in proc.stderr


@pytest.mark.slow
def test_the_player_declares_the_amplifier(tmp_path, stream_name) -> None:
    """--manufacturer, --model and --reference go into the stream's <acquisition> metadata,
    with each channel's label, unit and type, as the acquisition node reads them."""
    import mne

    from mindgrasp_eeg.lsl import StreamDescription

    raw = mne.io.RawArray(np.zeros((2, 200)), mne.create_info(['C3', 'C4'], 100.0, 'eeg'),
                          verbose='error')
    path = tmp_path / 'two_raw.fif'
    raw.save(path, verbose='error')
    player = start_player(stream_name, str(path), '--loop', '--duration', '60',
                          '--manufacturer', 'g.tec', '--model', 'g.Nautilus', '--reference',
                          'right earlobe')
    try:
        desc = StreamDescription.from_info(open_inlet(stream_name).info(timeout=30))
    finally:
        player.kill()
        player.wait()
    assert (desc.manufacturer, desc.model, desc.reference) == ('g.tec', 'g.Nautilus',
                                                               'right earlobe')
    assert desc.channel_names == ('C3', 'C4') and desc.channel_types == ('EEG', 'EEG')
    assert desc.channel_units == ('microvolts', 'microvolts')
