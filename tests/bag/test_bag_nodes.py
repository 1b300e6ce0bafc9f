"""Recorder and player nodes across processes over real DDS, and the ``mindgrasp bag`` CLI."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import numpy as np
import pytest
import yaml

from conftest_bag import EEG, PROBE, PUBLISHER, STRING, eeg_chunk, string
from mindgrasp_bag import BagReader

pytestmark = pytest.mark.slow

HERE = Path(__file__).parents[1]  # tests/: conftest_bag, for the child processes
N_EEG = 20


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env.setdefault('ROS_DOMAIN_ID', '16')
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    env['PYTHONUNBUFFERED'] = '1'
    return env


class _Lines:
    """Collect a process's stdout lines in a thread."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.lines: list[str] = []
        self.proc = proc
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            self.lines.append(line.rstrip('\n'))

    def wait_for(self, text: str, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if any(text in line for line in self.lines):
                return True
            if self.proc.poll() is not None:
                time.sleep(0.1)
                return any(text in line for line in self.lines)
            time.sleep(0.05)
        return False


def _start(args: list[str]) -> tuple[subprocess.Popen, _Lines]:
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            env=_env())
    return proc, _Lines(proc)


def _stop(proc: subprocess.Popen, sig: int = signal.SIGINT, timeout: float = 15.0) -> int:
    if proc.poll() is None:
        proc.send_signal(sig)
    try:
        return proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        return proc.wait(5)


@pytest.fixture(scope='module')
def recorded(tmp_path_factory):
    """Record a publisher process with the recorder node (all topics under a unique prefix)."""
    prefix = f'/bagtest_{uuid.uuid4().hex[:8]}'
    bag = tmp_path_factory.mktemp('nodes') / 'session'
    recorder, rec_out = _start([
        sys.executable, '-m', 'mindgrasp_bag.recorder_node', '--ros-args',
        '-p', f'output:={bag}', '-p', f'regex:="^{prefix}/"', '-p', 'discovery_period:=0.2'])
    publisher = None
    try:
        assert rec_out.wait_for('Recording to', 20), rec_out.lines
        # Started after the recorder: its topics must be discovered while recording.
        publisher, pub_out = _start([sys.executable, '-c', PUBLISHER, str(HERE), prefix,
                                     str(N_EEG)])
        assert pub_out.wait_for('done', 60), pub_out.lines + rec_out.lines
        assert publisher.wait(15) == 0, pub_out.lines
    finally:
        if publisher is not None and publisher.poll() is None:
            _stop(publisher)
        code = _stop(recorder)
        rec_out.thread.join(30)   # the last lines may still be in the pipe when it has ended
    assert code == 0, rec_out.lines
    return prefix, bag, rec_out.lines


def _expected(prefix: str) -> dict[str, list[bytes]]:
    return {f'{prefix}/eeg': [eeg_chunk(25 * k) for k in range(N_EEG)],
            f'{prefix}/chatter': [string(f'message {k}') for k in range(int(N_EEG * 100 / 130))]}


def test_recorder_node_records_discovered_topics_byte_exact(recorded):
    prefix, bag, log = recorded
    assert (bag / 'metadata.yaml').exists(), log
    assert any(f'Subscribed to {prefix}/eeg' in line for line in log), log
    with BagReader(bag) as reader:
        assert reader.complete
        assert reader.topics[f'{prefix}/eeg'].type == EEG
        assert reader.topics[f'{prefix}/chatter'].type == STRING
        latched = reader.topics[f'{prefix}/chatter'].offered_qos_profiles
        assert latched and latched[0]['durability'] == 'transient_local'
        got: dict[str, list[bytes]] = {}
        for topic, _, data in reader.messages():
            got.setdefault(topic, []).append(data)
    expected = _expected(prefix)
    assert got.keys() == expected.keys()
    for topic, sent in expected.items():
        assert len(got[topic]) == len(sent), topic
        for data, original in zip(got[topic], sent, strict=True):
            # DDS pads a sample to a multiple of 4 bytes: the content itself is identical.
            assert data[:len(original)] == original
            assert data[len(original):] == bytes(len(data) - len(original)) and len(data) % 4 == 0
    assert any('Recorded' in line and '0 dropped' in line for line in log), log


def test_bag_info_cli_prints_counts_rates_and_types(recorded):
    prefix, bag, _ = recorded
    out = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'info', str(bag)],
                         capture_output=True, text=True, env=_env(), timeout=60)
    assert out.returncode == 0, out.stderr
    n_text = int(N_EEG * 100 / 130)
    assert f'Messages:          {N_EEG + n_text}' in out.stdout
    eeg_line = next(line for line in out.stdout.splitlines() if f'{prefix}/eeg ' in line)
    assert EEG in eeg_line and f'Count: {N_EEG:>7}' in eeg_line
    rate = float(eeg_line.split('Rate:')[1].split('Hz')[0])
    # published at 10 Hz; under load the timer fires late and then catches up, so the rate from
    # the first and last stamps of a short recording drifts: a loose bound, the count is exact
    assert 5.0 < rate < 20.0
    info = yaml.safe_load(subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'bag', 'info', str(bag), '--yaml'],
        capture_output=True, text=True, env=_env(), timeout=60).stdout)
    assert {t['name'] for t in info['topics']} == {f'{prefix}/eeg', f'{prefix}/chatter'}


def test_bag_play_cli_republishes_identical_bytes_with_original_timing(recorded):
    prefix, bag, _ = recorded
    out_prefix = f'/bagplay_{uuid.uuid4().hex[:8]}'
    probe, probe_out = _start([sys.executable, '-c', PROBE, f'{out_prefix}/eeg={EEG}',
                               f'{prefix}/chatter={STRING}', '/clock=rosgraph_msgs/msg/Clock'])
    try:
        assert probe_out.wait_for('ready', 20), probe_out.lines
        play = subprocess.run(
            [sys.executable, '-m', 'mindgrasp_cli', 'bag', 'play', str(bag),
             '--remap', f'{prefix}/eeg:={out_prefix}/eeg', '--priority', '20', '--delay', '1.0',
             '--clock', '20'],
            capture_output=True, text=True, env=_env(), timeout=120)
        assert play.returncode == 0, play.stdout + play.stderr
        time.sleep(0.5)
    finally:
        _stop(probe)
        probe_out.thread.join(30)   # every line read from the pipe before they are counted
    rows = [line.split() for line in probe_out.lines if line.startswith('/')]
    got_eeg = [r for r in rows if r[0] == f'{out_prefix}/eeg']
    got_text = [r for r in rows if r[0] == f'{prefix}/chatter']
    with BagReader(bag) as reader:
        recorded = {t: [(s, d) for topic, s, d in reader.messages() if topic == t]
                    for t in reader.topics}
    # The bytes on the wire are the bytes in the bag.
    assert [r[2] for r in got_eeg] == [hashlib.sha1(d).hexdigest()
                                       for _, d in recorded[f'{prefix}/eeg']]
    assert [r[2] for r in got_text] == [hashlib.sha1(d).hexdigest()
                                        for _, d in recorded[f'{prefix}/chatter']]
    # Relative timing: publication times (DDS source timestamps, taken by the player process)
    # against the bag's timestamps, relative to their median offset (not to the first message,
    # which alone may go out late on a loaded machine and shift every other error).
    stamps = np.array([s for s, _ in recorded[f'{prefix}/eeg']], dtype=np.int64)
    sent = np.array([int(r[1]) for r in got_eeg], dtype=np.int64)
    offset = sent - stamps
    errors = np.abs(offset - np.median(offset)) / 1e6
    assert np.median(errors) < 5.0 and errors.max() < 50.0, errors
    # --clock 20: /clock at ~20 Hz during the ~2 s of playback.
    assert 20 <= sum(1 for r in rows if r[0] == '/clock') <= 60


def test_bag_play_missing_bag_is_a_clear_error(tmp_path):
    out = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'play',
                          str(tmp_path / 'nope')], capture_output=True, text=True, env=_env(),
                         timeout=60)
    assert out.returncode == 2    # a bad argument: the node refuses to start
    assert 'does not exist; pass a run directory (runs/<run>) or its bag folder' in out.stderr


def test_recorder_node_full_disk_stops_recording_and_keeps_running(tmp_path):
    mount = tmp_path / 'tiny'
    mount.mkdir()
    result = subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=40k', 'tmpfs', str(mount)],
                            capture_output=True, text=True)
    if result.returncode != 0:
        pytest.skip(f'cannot mount a small tmpfs to fill (needs root): {result.stderr.strip()}')
    prefix = f'/bagfull_{uuid.uuid4().hex[:8]}'
    recorder = publisher = None
    try:
        # Through the CLI this time: `mindgrasp bag record`.
        recorder, rec_out = _start([
            sys.executable, '-m', 'mindgrasp_cli', 'bag', 'record', '-o', str(mount / 'bag'),
            '-e', f'^{prefix}/', '--flush-interval', '0.2', '--duration', '60'])
        assert rec_out.wait_for('Recording to', 20), rec_out.lines
        publisher, pub_out = _start([sys.executable, '-c', PUBLISHER, str(HERE), prefix, '30'])
        assert rec_out.wait_for('Recording stopped', 60), rec_out.lines + pub_out.lines
        assert any('disk is full' in line for line in rec_out.lines), rec_out.lines
        assert pub_out.wait_for('done', 60), pub_out.lines
        assert recorder.poll() is None            # the node keeps running after the error
        assert _stop(recorder) == 1               # ... and reports the failure when it ends
        with BagReader(mount / 'bag') as reader:
            got = [d for topic, _, d in reader.messages() if topic == f'{prefix}/eeg']
        assert got, 'nothing written before the disk filled up was kept'
        for k, data in enumerate(got):
            assert data[:len(eeg_chunk(25 * k))] == eeg_chunk(25 * k)
    finally:
        for proc in (publisher, recorder):
            if proc is not None and proc.poll() is None:
                _stop(proc)
        subprocess.run(['umount', '-l', str(mount)], check=False)


def test_bag_record_bad_options_are_clear_errors(tmp_path):
    # a number out of range is an argparse error, a regex is checked by the recorder's
    # parameters: both exit 2
    for extra, code, message in (
            (['-e', '('], 2, 'The topic regular expression is not valid'),
            (['--compression', 'zstd', '--max-queue-mb', '0'], 2,
             'argument --max-queue-mb: must be >= 1, got 0')):
        out = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'record',
                              '-o', str(tmp_path / uuid.uuid4().hex), *extra],
                             capture_output=True, text=True, env=_env(), timeout=60)
        assert out.returncode == code and message in out.stderr, out.stderr
