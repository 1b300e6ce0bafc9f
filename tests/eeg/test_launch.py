"""`mindgrasp launch eeg eeg_stream:=NAME marker_stream:=auto` records an EEGMMIDB file played by
the LSL player, with the player's marker stream (the file's annotations) on /eeg/markers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_eeg.export import read_session
from mindgrasp_eeg.player import load_recording

from .test_player import eegbci_file


@pytest.mark.slow
def test_launch_eeg_records_a_played_dataset(tmp_path: Path, stream_name: str) -> None:
    path = eegbci_file(8)
    player = subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'eeg', 'play', path,
                               '--name', stream_name, '--duration', '60'],
                              stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        assert player.stdout is not None and 'Playing' in player.stdout.readline()
        run = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'launch', 'eeg',
                              f'eeg_stream:={stream_name}', 'marker_stream:=auto',
                              '--duration', '12', '--run-dir',
                              str(tmp_path / 'run')], capture_output=True, text=True, timeout=120)
    finally:
        player.kill()
        player.wait()
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    assert 'adopting the stream' in run.stdout + run.stderr  # 64 ch @ 160 Hz, not 32 @ 250
    session = read_session(tmp_path / 'run')
    assert session.rate == 160.0 and len(session.channels) == 64
    assert session.channels[:3] == ['FC5', 'FC3', 'FC1']
    assert len(session.data) > 3 * 160 and session.n_missing == 0
    rec = load_recording(path)
    k0 = int(np.argmin(np.abs(rec.data[:20000] - session.data[0]).sum(axis=1)))
    np.testing.assert_allclose(session.data, rec.data[k0:k0 + len(session.data)], atol=1e-9)
    # the file's annotations came as LSL markers and are recorded at their samples (1 sample)
    file_onsets = {round(on * 160): desc for on, _d, desc in rec.annotations}
    markers = [(on, desc) for on, _d, desc in session.annotations if desc in ('T0', 'T1', 'T2')]
    for on, desc in markers:
        k = k0 + round(on * 160)
        near = [file_onsets.get(k + d) for d in (-1, 0, 1)]
        assert desc in near, (on, desc, k)
    if len(session.data) > 9 * 160:         # two annotation periods (4.2 s) recorded
        assert markers, session.annotations
    # the classifier's bag loader labels epochs by those markers (T1 left, T2 right fist)
    from mindgrasp_classifier.data import load_bag

    labelled = load_bag(tmp_path / 'run', labels='markers', event_map={'T1': 0, 'T2': 1})
    expected = [(round(on * 160), {'T1': 0, 'T2': 1}[desc]) for on, desc in markers
                if desc != 'T0']
    assert len(labelled.events) == len(expected)
    for (onset, cls), (want_onset, want_cls) in zip(labelled.events, expected, strict=True):
        assert cls == want_cls and abs(onset - want_onset) <= 1, (labelled.events, expected)
