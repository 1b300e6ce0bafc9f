"""Recorder core: background writing, drop and gap reports, SIGKILL, full disk."""

from __future__ import annotations

import errno
import io
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
import uuid
from pathlib import Path

import pytest
from rosbags.rosbag2 import Reader as RosbagsReader

from conftest_bag import EEG, IMAGE, STRING, eeg_chunk, image, string
from mindgrasp_bag import BagReader, BagWriter, Recorder
from mindgrasp_cli.cli import main as cli_main
from mindgrasp_testing import small_tmpfs


def test_messages_from_many_threads_are_all_written(tmp_path):
    recorder = Recorder(BagWriter(tmp_path / 'bag'))
    recorder.start()
    recorder.add_topic('/a', STRING)
    recorder.add_topic('/b', STRING)

    def produce(topic: str) -> None:
        for i in range(500):
            assert recorder.push(topic, string(f'{topic} {i}'), 1_000 + i)

    threads = [threading.Thread(target=produce, args=(t,)) for t in ('/a', '/b')]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    counters = recorder.stop()
    assert counters['/a'].written == counters['/b'].written == 500
    assert recorder.error is None
    with BagReader(tmp_path / 'bag') as reader:
        got = [d for topic, _, d in reader.messages() if topic == '/a']
    assert got == [string(f'/a {i}') for i in range(500)]


def test_full_queue_drops_are_counted_and_reported(tmp_path):
    data = image(1, 64, 64)
    recorder = Recorder(BagWriter(tmp_path / 'bag'), max_queue_bytes=3 * len(data))
    recorder.add_topic('/camera/color/image_raw', IMAGE)
    # Writer thread not started yet: the queue fills, the rest is dropped without blocking.
    accepted = [recorder.push('/camera/color/image_raw', data, i) for i in range(10)]
    assert accepted == [True] * 3 + [False] * 7
    reports = recorder.reports()
    assert len(reports) == 1
    assert 'dropped 7 message(s) because the write queue was full' in reports[0]
    assert recorder.reports() == []         # reported once
    recorder.start()
    counters = recorder.stop()
    assert counters['/camera/color/image_raw'].written == 3
    assert counters['/camera/color/image_raw'].dropped_queue_full == 7


def test_eeg_sample_gaps_are_detected(tmp_path):
    recorder = Recorder(BagWriter(tmp_path / 'bag'))
    recorder.start()
    recorder.add_topic('/eeg/raw', EEG)
    for k, first in enumerate([0, 25, 50, 100, 125, 175]):     # 25 + 25 samples missing
        recorder.push('/eeg/raw', eeg_chunk(first), k)
    counters = recorder.stop()
    assert counters['/eeg/raw'].gaps == 2
    assert counters['/eeg/raw'].samples_missing == 50
    reports = recorder.reports()
    assert any('25 EEG sample(s) missing before sample 100' in r for r in reports)


CHILD = textwrap.dedent('''
    import sys, time
    sys.path.insert(0, sys.argv[2])
    from conftest_bag import image
    from mindgrasp_bag import BagWriter, Recorder
    recorder = Recorder(BagWriter(sys.argv[1], flush_interval=0.2))
    recorder.start()
    recorder.add_topic('/camera/color/image_raw', 'sensor_msgs/msg/Image')
    k = 0
    while True:
        recorder.push('/camera/color/image_raw', image(k, 32, 24), 1_000_000 * k)
        k += 1
        print(k, time.monotonic(), flush=True)
        time.sleep(0.01)
''')


def on_disk(bag: Path) -> int:
    """Messages a reader finds in the (possibly unfinished) bag right now; 0 before any flush."""
    try:
        with BagReader(bag) as reader:
            return sum(1 for _ in reader.messages())
    except Exception:  # not written yet, or cut mid-chunk: nothing readable
        return 0


@pytest.mark.slow
def test_sigkill_during_recording_leaves_a_readable_bag(tmp_path, capsys):
    bag = tmp_path / 'killed'
    tests = str(Path(__file__).parents[1])    # conftest_bag
    proc = subprocess.Popen([sys.executable, '-c', CHILD, str(bag), tests],
                            stdout=subprocess.PIPE, text=True)
    lines, flushed = [], 0
    deadline = time.monotonic() + 120
    try:
        for line in proc.stdout:
            lines.append(line.split())
            # Kill once the writer has flushed a good part of the recording to disk: a condition
            # (what a reader sees in the file), not a duration, since a loaded machine flushes late.
            if len(lines) % 10 == 0:
                flushed = on_disk(bag)
                if flushed >= 50 or time.monotonic() > deadline:
                    break
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
        proc.stdout.close()
    assert flushed >= 50, f'the writer flushed {flushed} message(s) of {len(lines)} pushed'
    assert not (bag / 'metadata.yaml').exists()
    with BagReader(bag) as reader:
        assert not reader.complete
        got = [d for _, _, d in reader.messages()]
    # Nothing that was on disk before the kill is lost, and what is there is intact and in order.
    with capsys.disabled():     # the figure for the reliability note (-s)
        print(f'\nKILLED RECORDER kept {len(got)} of {len(lines)} pushed messages (100 Hz; '
              f'{len(lines) - len(got)} in the last flush interval)')
    assert len(got) >= flushed
    assert got == [image(k, 32, 24) for k in range(len(got))]
    # bag info reads the unfinished file, reports the damage (exit 1) and writes nothing
    capsys.readouterr()
    before = sorted(p.name for p in bag.iterdir())
    assert cli_main(['bag', 'info', str(bag)]) == 1
    out = capsys.readouterr().out
    assert f'Messages:          {len(got)}' in out
    assert 'metadata.yaml is missing; run `mindgrasp bag reindex' in out
    assert sorted(p.name for p in bag.iterdir()) == before      # read-only
    assert 'without a footer (the recorder was killed)' in out
    assert cli_main(['bag', 'info', '--allow-damaged', str(bag)]) == 0
    # --fix finishes the file, so tools without a recovery path (rosbags) read it too.
    assert cli_main(['bag', 'info', '--fix', str(bag)]) == 0
    assert 'rewritten with its summary' in capsys.readouterr().out
    with RosbagsReader(bag) as reader:
        assert [bytes(d) for _, _, d in reader.messages()] == got


@pytest.fixture
def tiny_disk(tmp_path):
    """A 1 MiB tmpfs (needs root); skipped where mounting is not allowed."""
    with small_tmpfs(tmp_path / f'tiny-{uuid.uuid4().hex[:6]}', '1m') as mount:
        yield mount


def test_full_disk_stops_recording_with_an_error_and_keeps_what_was_written(tiny_disk):
    errors = []
    recorder = Recorder(BagWriter(tiny_disk / 'bag', chunk_size=64 << 10, flush_interval=0.0),
                        on_error=errors.append)
    recorder.start()
    recorder.add_topic('/camera/color/image_raw', IMAGE)
    frames = [image(k, 160, 120) for k in range(40)]     # 57.6 kB each: 2.3 MB > 1 MiB
    for k, frame in enumerate(frames):
        recorder.push('/camera/color/image_raw', frame, k)
        time.sleep(0.005)
    recorder.stop()
    assert len(errors) == 1
    assert 'disk is full; free space or record to another disk' in errors[0]
    assert recorder.error == errors[0]
    assert recorder.push('/camera/color/image_raw', frames[0], 99) is False   # stopped
    with BagReader(tiny_disk / 'bag') as reader:
        got = [d for _, _, d in reader.messages()]
    assert 3 <= len(got) < len(frames)
    assert got == frames[:len(got)]


class _FullDisk(io.RawIOBase):
    """A file on a disk with ``budget`` bytes free: then ENOSPC, after a partial write."""

    def __init__(self, path: Path, budget: int) -> None:
        self._f = open(path, 'xb', buffering=0)  # noqa: SIM115 (closed by close())
        self.budget = budget
        self.name = str(path)

    def writable(self) -> bool:
        return True

    def write(self, b) -> int:
        if self.budget <= 0:
            raise OSError(errno.ENOSPC, 'No space left on device')
        n = self._f.write(bytes(b[:self.budget]))
        self.budget -= n
        return n

    def tell(self) -> int:
        return self._f.tell()

    def close(self) -> None:
        self._f.close()
        super().close()


def test_full_disk_counts_are_what_the_bag_really_holds(tmp_path, monkeypatch):
    real_open = Path.open

    def open_on_small_disk(self, mode='r', *args, **kwargs):
        if mode == 'xb':
            return io.BufferedWriter(_FullDisk(self, 40_000), 1 << 20)
        return real_open(self, mode, *args, **kwargs)

    monkeypatch.setattr(Path, 'open', open_on_small_disk)
    errors = []
    # chunks of ~8 KiB written out by size: some reach the disk between flushes, the last is cut
    recorder = Recorder(BagWriter(tmp_path / 'bag', chunk_size=8_000, flush_interval=60.0),
                        on_error=errors.append)
    recorder.add_topic('/a', STRING)
    recorder.start()
    for i in range(200):
        recorder.push('/a', string(f'{i:04d}' + 'x' * 500), 1_000 + i)
        time.sleep(0.001)
    counters = recorder.stop()['/a']
    monkeypatch.undo()
    assert recorder.error is not None and len(errors) == 1
    with BagReader(tmp_path / 'bag') as reader:
        readable = sum(1 for _ in reader.messages())
    assert 0 < readable < 200
    assert counters.written == readable          # the count is what can be recovered
    assert counters.written + counters.lost_disk_fault == counters.received == 200
    assert f'{readable} message(s) are on disk and recoverable' in errors[0]
    assert f'{200 - readable - int(errors[0].split(" queued")[0].split()[-1])} written before ' \
        'the fault did not reach the disk' in errors[0]
