"""Acquisition core against real LSL outlets in other processes."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.acquisition import ERROR, OK, WARN, EEGAcquisition, ros_stamp_ns
from mindgrasp_eeg.montage import NAUTILUS_32

pytestmark = pytest.mark.slow


def collect(acq: EEGAcquisition, n_samples: int, until=None, timeout: float = 60.0,
            period: float = 1 / 32):
    """Poll until ``n_samples`` samples (and ``until()``, if given) or ``timeout`` s: a condition,
    not a duration, since a loaded machine delivers late."""
    chunks, t_end = [], time.monotonic() + timeout
    while time.monotonic() < t_end:
        chunks.extend(acq.poll())
        if sum(len(c.data) for c in chunks) >= n_samples and (until is None or until()):
            break
        time.sleep(period)
    return chunks


def test_acquires_from_a_real_outlet(lsl_source, stream_name) -> None:
    lsl_source(stream_name, '--duration', '120')
    acq = EEGAcquisition(stream_name, n_channels=32, sample_rate=250, channel_names=NAUTILUS_32)
    desc = acq.connect(timeout=30)
    assert desc.channel_names == NAUTILUS_32 and desc.unit == 'microvolts'
    chunks = collect(acq, 3 * 250)
    data = np.vstack([c.data for c in chunks])
    ts = np.concatenate([c.timestamps for c in chunks])
    assert len(data) >= 3 * 250
    assert data.dtype == np.float32 and data.shape[1] == 32
    assert 3e-6 < float(np.std(data)) < 50e-6          # microvolts on the wire, volts out
    assert np.all(np.diff(ts) > 0)
    np.testing.assert_allclose(np.diff(ts), 1 / 250, atol=2e-4)
    idx = [c.first_index for c in chunks]
    sizes = [len(c.data) for c in chunks]
    assert idx[0] == 0 and all(i + n == j for i, n, j in zip(idx, sizes, idx[1:], strict=False))
    assert acq.counters['dropped'] == 0 and acq.counters['out_of_order'] == 0
    assert acq.status().level == OK
    acq.close()


def test_resolve_timeout_lists_visible_streams(lsl_source, stream_name) -> None:
    lsl_source(stream_name, '--duration', '120')
    acq = EEGAcquisition(stream_name + '_missing')
    with pytest.raises(EEGError, match=rf"No LSL stream with name='{stream_name}_missing'.*"
                                       rf"Visible streams:.*'{stream_name}' \(type 'EEG', 32 ch"):
        acq.connect(timeout=0.5)


def test_layout_validation_and_adaptation(lsl_source, stream_name) -> None:
    lsl_source(stream_name, '--n-channels', '8', '--rate', '160', '--duration', '120')
    with pytest.raises(EEGError, match=r'has 8 channels, expected 32 .*runs at 160 Hz, expected '
                                       r'250 Hz.*adapt_to_stream'):
        EEGAcquisition(stream_name, n_channels=32, sample_rate=250).connect(timeout=30)
    with pytest.raises(EEGError, match=r"has channels \[E1, E2, .*expected \[X0"):
        EEGAcquisition(stream_name, channel_names=[f'X{k}' for k in range(8)]).connect(timeout=30)
    acq = EEGAcquisition(stream_name, n_channels=32, sample_rate=250, adapt=True)
    desc = acq.connect(timeout=30)
    assert desc.n_channels == 8 and desc.sample_rate == 160
    assert any('adopting' in w for w in acq.warnings)
    chunks = collect(acq, 160)
    assert chunks and chunks[0].data.shape[1] == 8
    acq.close()


@pytest.mark.parametrize('policy', ['replace', 'drop'])
def test_nan_flat_railed_are_flagged(lsl_source, stream_name, policy) -> None:
    lsl_source(stream_name, '--nan-channel', '3', '--flat-channel', '5', '--railed-channel', '7',
               '--duration', '120')
    acq = EEGAcquisition(stream_name, nan_policy=policy)
    acq.connect(timeout=30)
    chunks = collect(acq, 625 if policy == 'replace' else 1,
                     until=lambda: acq.counters['nonfinite_samples'] > 100)
    status = acq.status()
    assert status.level == WARN
    assert f'NaN/inf on {NAUTILUS_32[3]}' in status.message
    assert f'flat on {NAUTILUS_32[5]}' in status.message
    assert f'railed on {NAUTILUS_32[7]}' in status.message
    data = np.vstack([c.data for c in chunks])
    assert np.isfinite(data).all()
    assert acq.counters['nonfinite_samples'] > 100
    if policy == 'drop':
        assert acq.counters['nan_dropped'] == acq.counters['nonfinite_samples']
        assert len(data) < 0.8 * acq.counters['samples']
    else:
        assert len(data) == acq.counters['samples']
    acq.close()


def test_dropped_and_out_of_order_samples_are_counted(lsl_source, stream_name) -> None:
    lsl_source(stream_name, '--gap-at', '1.0', '--gap-samples', '50', '--disorder-at', '1.5',
               '--duration', '120')
    acq = EEGAcquisition(stream_name, dejitter=False)     # raw amplifier stamps
    acq.connect(timeout=30)
    chunks = collect(acq, 2 * 250, until=lambda: acq.counters['out_of_order'] >= 1)
    assert acq.counters['dropped'] == 50
    assert acq.counters['out_of_order'] == 1
    idx = np.concatenate([c.first_index + np.arange(len(c.data)) for c in chunks])
    assert np.all(np.diff(idx) >= 1) and np.sum(np.diff(idx) - 1) == 50
    acq.close()


def test_stream_loss_and_reconnection(lsl_source, stream_name) -> None:
    amp = lsl_source(stream_name, '--duration', '120')
    acq = EEGAcquisition(stream_name, lost_timeout=0.5)
    acq.connect(timeout=30)
    collect(acq, 250)
    before = acq.counters['samples']
    amp.kill()
    amp.wait()
    t_kill = time.monotonic()
    while acq.status().level != ERROR and time.monotonic() - t_kill < 60:
        acq.poll()
        time.sleep(0.02)
    detected_after = time.monotonic() - t_kill
    status = acq.status()
    assert status.level == ERROR and 'is lost (the sender closed the connection' in status.message
    assert detected_after < 5.0                 # a closed connection is reported at once
    time.sleep(0.5)
    lsl_source(stream_name, '--duration', '120')            # a new amplifier process
    t_new = time.monotonic()
    while not acq.connected and time.monotonic() - t_new < 60:
        acq.poll()
        time.sleep(0.05)
    assert acq.connected, acq.status().message
    chunks = collect(acq, 250, until=lambda: acq.counters['samples'] > before + 150)
    assert acq.counters['reconnects'] >= 1 and acq.counters['losses'] >= 1
    assert acq.counters['samples'] > before + 150
    assert acq.counters['dropped'] > 100                  # the outage shows up as a gap
    assert chunks[-1].first_index > before
    assert acq.status().level == OK
    acq.close()


def test_stalled_stream_is_lost_after_timeout(lsl_source, stream_name) -> None:
    lsl_source(stream_name, '--stall-at', '1.0', '--stall-len', '2.5', '--duration', '120')
    acq = EEGAcquisition(stream_name, lost_timeout=0.5)
    acq.connect(timeout=30)
    t0 = time.monotonic()
    last_data = t0
    while acq.status().level != ERROR and time.monotonic() - t0 < 60:
        if acq.poll():
            last_data = time.monotonic()
        time.sleep(0.01)
    # lost no earlier than lost_timeout (0.5 s) after the last data; the upper bound only says
    # "before the stream resumes" (2.5 s stall), as this loop may be scheduled late
    assert acq.lost and 0.45 < time.monotonic() - last_data < 2.0
    while not acq.connected and time.monotonic() - t0 < 60:
        acq.poll()
        time.sleep(0.05)
    collect(acq, 125)
    assert acq.connected and acq.counters['reconnects'] >= 1 and acq.status().level == OK
    acq.close()


def test_ros_stamp_keeps_sample_age() -> None:
    assert ros_stamp_ns(99.5, 100.0, 1_000_000_000_000) == 1_000_000_000_000 - 500_000_000


def test_bad_parameters() -> None:
    with pytest.raises(EEGError, match='nan_policy must be one of'):
        EEGAcquisition('x', nan_policy='ignore')
    with pytest.raises(EEGError, match="EEG unit 'furlongs' is unknown"):
        EEGAcquisition('x', stream_unit='furlongs')
    with pytest.raises(EEGError, match='No LSL stream selector given'):
        EEGAcquisition('', stream_type='').connect(timeout=0.1)


@pytest.mark.parametrize(('unit', 'scale'), [
    ('microvolts', 1e-6), ('uV', 1e-6), ('µV', 1e-6), ('V', 1.0), ('volts', 1.0),
    ('mV', 1e-3), ('nanovolts', 1e-9),
    ('0', 1.0), ('-6', 1e-6), ('-3', 1e-3), ('-9', 1e-9), ('+0', 1.0),   # MNE-LSL exponents
])
def test_units_of_other_lsl_tools(unit, scale) -> None:
    from mindgrasp_eeg.lsl import unit_scale

    assert unit_scale(unit) == pytest.approx(scale)


def test_mne_lsl_style_exponent_unit_from_a_real_outlet(lsl_source, stream_name) -> None:
    """A stream whose channels say "-6" (MNE-LSL's PlayerLSL for microvolts) is read in volts."""
    lsl_source(stream_name, '--unit=-6', '--duration', '120')
    acq = EEGAcquisition(stream_name, n_channels=32, sample_rate=250, channel_names=NAUTILUS_32)
    desc = acq.connect(timeout=30)
    assert desc.unit == '-6' and acq.scale == pytest.approx(1e-6)
    data = np.vstack([c.data for c in collect(acq, 250)])
    assert 3e-6 < float(np.std(data)) < 50e-6            # microvolts on the wire, volts out
    acq.close()


def test_an_edf_played_by_mne_lsl_playerlsl_is_read_in_volts(stream_name) -> None:
    """MNE-LSL's PlayerLSL (another process) streams EEGMMIDB S001R04 with the unit "0"
    (volts as a power-of-ten exponent); the samples arrive in volts, equal to the file's."""
    import mne

    from .test_player import eegbci_file

    path = eegbci_file(4)
    proc = subprocess.Popen([sys.executable, str(Path(__file__).with_name('mne_lsl_player.py')),
                             path, stream_name], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout is not None and proc.stdout.readline().strip() == 'READY'
        acq = EEGAcquisition(stream_name, stream_type='', adapt=True)
        desc = acq.connect(timeout=60)
        assert (desc.n_channels, desc.sample_rate, desc.unit) == (64, 160.0, '0')
        assert acq.scale == 1.0
        data = np.vstack([c.data for c in collect(acq, 2 * 160)])
        acq.close()
    finally:
        proc.kill()
        proc.wait(30)
    raw = mne.io.read_raw_edf(path, preload=True, verbose=False).get_data().T   # volts
    # the player loops over the file from an unknown start: find the received block in it
    n = 32
    starts = [k for k in range(len(raw) - n)
              if np.allclose(raw[k:k + n, 0], data[:n, 0], rtol=1e-5, atol=1e-9)]
    assert len(starts) == 1, f'{len(starts)} matches of the first received samples'
    k = starts[0]
    m = min(len(data), len(raw) - k)
    np.testing.assert_allclose(data[:m], raw[k:k + m], rtol=1e-5, atol=1e-9)


def test_amplifier_metadata_after_the_xdf_conventions() -> None:
    """<acquisition> manufacturer/model/reference, the EEG convention's <reference><label>, each
    channel's unit and type; a stream that declares none gives empty strings."""
    import pylsl

    from mindgrasp_eeg.lsl import StreamDescription

    info = pylsl.StreamInfo('amp', 'EEG', 2, 500.0, pylsl.cf_float32, 'amp-1')
    chans = info.desc().append_child('channels')
    for label, unit, kind in (('C3', 'microvolts', 'EEG'), ('HEOG', 'microvolts', 'EOG')):
        ch = chans.append_child('channel')
        ch.append_child_value('label', label)
        ch.append_child_value('unit', unit)
        ch.append_child_value('type', kind)
    acq = info.desc().append_child('acquisition')
    acq.append_child_value('manufacturer', 'Brain Products')
    acq.append_child_value('model', 'BrainAmp DC')
    ref = info.desc().append_child('reference')
    ref.append_child_value('label', 'TP9')
    ref.append_child_value('label', 'TP10')
    desc = StreamDescription.from_info(info)
    assert (desc.manufacturer, desc.model, desc.reference) == ('Brain Products', 'BrainAmp DC',
                                                               'TP9, TP10')
    assert desc.channel_units == ('microvolts', 'microvolts')
    assert desc.channel_types == ('EEG', 'EOG') and desc.unit == 'microvolts'
    bare = StreamDescription.from_info(pylsl.StreamInfo('bare', 'EEG', 2, 250.0))
    assert (bare.manufacturer, bare.model, bare.reference, bare.channel_units) == ('', '', '', ())
