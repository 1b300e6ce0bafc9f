"""Export round trip: a rosbag2 (MCAP) with /eeg/raw, prompts and targets -> FIF/EDF -> MNE."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mne
import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.export import _typestore, export_session, read_session
from mindgrasp_eeg.montage import standard_montage

FS, NAMES = 250.0, ['C3', 'Cz', 'C4']
T0_NS = 1_700_000_000_000_000_000


def write_bag(run_dir: Path, data: np.ndarray, gap: tuple[int, int]) -> None:
    """10-sample chunks of ``data`` on /eeg/raw, minus the samples in ``gap``; two prompts and
    a target."""
    store = _typestore()
    chunk_cls = store.types['mindgrasp_msgs/msg/EEGChunk']
    header_cls = store.types['std_msgs/msg/Header']
    time_cls = store.types['builtin_interfaces/msg/Time']

    def header(ns: int):
        return header_cls(stamp=time_cls(sec=ns // 10**9, nanosec=ns % 10**9), frame_id='eeg')

    prompt_cls = store.types['mindgrasp_msgs/msg/Prompt']
    target_cls = store.types['mindgrasp_msgs/msg/TaskTarget']
    result_cls = store.types['mindgrasp_msgs/msg/GraspResult']
    state_cls = store.types['mindgrasp_msgs/msg/FsmState']
    with Writer(run_dir / 'bag', version=9, storage_plugin=StoragePlugin.MCAP) as w:
        c_eeg = w.add_connection('/eeg/raw', 'mindgrasp_msgs/msg/EEGChunk', typestore=store)
        c_pr = w.add_connection('/trainer/prompt', 'mindgrasp_msgs/msg/Prompt', typestore=store)
        c_tg = w.add_connection('/task/target', 'mindgrasp_msgs/msg/TaskTarget', typestore=store)
        c_rs = w.add_connection('/task/result', 'mindgrasp_msgs/msg/GraspResult',
                                typestore=store)
        c_st = w.add_connection('/fsm/state', 'mindgrasp_msgs/msg/FsmState', typestore=store)
        # controller states published periodically: annotations only at changes
        # the first state message comes before the EEG: the state holds from sample 0 on
        for at, state, name in ((-0.3, 1, 'OBJECT_SEARCH'), (0.4, 1, 'OBJECT_SEARCH'),
                                (1.2, 2, 'CENTER_OBJECT'), (1.4, 2, 'CENTER_OBJECT')):
            ns = T0_NS + int(at * 1e9)
            msg = state_cls(header=header(ns), state=state, state_name=name)
            w.write(c_st, ns, store.serialize_cdr(msg, c_st.msgtype))
        ns = T0_NS + int(3.5 * 1e9)
        msg = result_cls(header=header(ns), trial=1, desired_object='red cube',
                         grasped_object='red cube', success=True, duration=3.0)
        w.write(c_rs, ns, store.serialize_cdr(msg, c_rs.msgtype))
        for first in range(0, len(data), 10):
            if gap[0] <= first < gap[1]:
                continue
            stamp = T0_NS + round(first / FS * 1e9)
            block = data[first:first + 10].astype(np.float32)
            msg = chunk_cls(header=header(stamp), sample_rate=FS, channel_names=NAMES,
                            n_samples=len(block), first_sample_index=first + 500, unit='V',
                            data=block.ravel())
            w.write(c_eeg, stamp, store.serialize_cdr(msg, c_eeg.msgtype))
        for onset, phase, cls in ((1.0, 'cue', 0), (3.0, 'rest', 255)):
            ns = T0_NS + int(onset * 1e9)
            msg = prompt_cls(header=header(ns), paradigm='graz', class_index=cls,
                             class_name='', phase=phase, trial=1, duration=1.5)
            w.write(c_pr, ns, store.serialize_cdr(msg, c_pr.msgtype))
        ns = T0_NS + int(0.5 * 1e9)
        msg = target_cls(header=header(ns), trial=1, object_id=3, colour='red', shape='cube',
                         scene='set_locations')
        w.write(c_tg, ns, store.serialize_cdr(msg, c_tg.msgtype))


@pytest.fixture
def run_dir(tmp_path: Path) -> tuple[Path, np.ndarray]:
    rng = np.random.default_rng(0)
    data = rng.normal(0, 20e-6, (1000, 3))                  # 4 s of EEG-sized values (V)
    write_bag(tmp_path, data, gap=(400, 450))               # 50 samples never received
    return tmp_path, data


def test_session_from_bag(run_dir) -> None:
    path, data = run_dir
    s = read_session(path)
    assert s.rate == FS and s.channels == NAMES and s.start_ns == T0_NS
    assert s.data.shape == (1000, 3) and s.n_missing == 50
    np.testing.assert_allclose(s.data[:400], data[:400].astype(np.float32))
    assert ('BAD_gap' in [a[2] for a in s.annotations])


@pytest.mark.parametrize('fmt', ['fif', 'edf'])
def test_export_round_trip_through_mne(run_dir, fmt: str, recwarn) -> None:
    path, data = run_dir
    out = export_session(path, fmt=fmt)
    # MNE 1.13 deprecated the 'standard_1020' name: every export printed its FutureWarning
    assert [str(w.message) for w in recwarn if issubclass(w.category, FutureWarning)] == []
    assert out.parent == path and out.is_file()
    reader = mne.io.read_raw_fif if fmt == 'fif' else mne.io.read_raw_edf
    raw = reader(out, preload=True, verbose='error')
    assert raw.info['sfreq'] == FS and raw.ch_names == NAMES
    got = raw.get_data().T[:1000]
    atol = 1e-10 if fmt == 'fif' else 2e-8                 # EDF: 16-bit per-channel scaling
    np.testing.assert_allclose(got[:400], data[:400], atol=atol)
    np.testing.assert_allclose(got[450:], data[450:], atol=atol)
    ann = {d: (o, dur) for o, dur, d in zip(raw.annotations.onset, raw.annotations.duration,
                                            raw.annotations.description, strict=True)}
    assert ann['prompt/cue/left_hand'][0] == pytest.approx(1.0, abs=1 / FS)
    assert ann['prompt/cue/left_hand'][1] == pytest.approx(1.5, abs=1 / FS)
    assert ann['prompt/rest/rest'][0] == pytest.approx(3.0, abs=1 / FS)
    assert ann['target/red cube'] == pytest.approx((0.5, 3.5), abs=1 / FS)   # to the end
    assert ann['BAD_gap'][0] == pytest.approx(1.6, abs=1 / FS)
    assert ann['BAD_gap'][1] == pytest.approx(0.2, abs=1 / FS)
    assert ann['result/success/red cube'] == pytest.approx((0.5, 3.0), abs=1 / FS)
    assert ann['state/1 OBJECT_SEARCH'] == pytest.approx((0.0, 1.2), abs=1 / FS)
    assert ann['state/2 CENTER_OBJECT'][0] == pytest.approx(1.2, abs=1 / FS)
    assert list(raw.annotations.description).count('state/1 OBJECT_SEARCH') == 1
    _events, ids = mne.events_from_annotations(raw, verbose='error')
    assert 'prompt/cue/left_hand' in ids and 'result/success/red cube' in ids
    if fmt == 'edf':      # EDF stores no electrode positions: the reader sets the montage
        raw.set_montage(standard_montage())
    positions = raw.get_montage().get_positions()['ch_pos']
    assert set(positions) == set(NAMES)                     # standard 10-20 positions
    assert positions['C3'][0] < 0 < positions['C4'][0]      # left and right of the head


def test_export_errors(tmp_path, run_dir) -> None:
    with pytest.raises(EEGError, match='neither a run directory with a bag nor a rosbag2'):
        read_session(tmp_path / 'nothing')
    path, _ = run_dir
    with pytest.raises(EEGError, match="holds no EEG on '/eeg/other'"):
        read_session(path, '/eeg/other')
    with pytest.raises(EEGError, match='format must be one of'):
        export_session(path, fmt='csv')
    export_session(path)
    with pytest.raises(EEGError, match='exists already; pass --overwrite'):
        export_session(path)


def test_cli(run_dir) -> None:
    path, _ = run_dir
    out = path / 'x.edf'
    proc = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'export', 'eeg', str(path),
                           '--format', 'edf', '-o', str(out)], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert '1000 samples x 3 channels at 250 Hz' in proc.stdout and out.is_file()


def test_the_classifier_reads_the_same_recording(run_dir) -> None:
    """The exporter and the classifier's trainer read a run into one type, with the same samples,
    gaps and start time."""
    from mindgrasp_classifier.data import load_bag

    path, _data = run_dir
    exported, trained = read_session(path), load_bag(path)
    assert exported.channels == trained.channels and exported.rate == trained.rate
    assert exported.first_sample_index == trained.first_sample_index
    np.testing.assert_array_equal(exported.data, trained.data)     # NaN in the same gap
    assert exported.n_missing == trained.n_missing == 50
    assert abs(exported.start_ns - trained.start_ns) < 1e9 / FS
