"""Player core: original timing, rate, offset, loop, filters, remap, /clock, skipped types."""

from __future__ import annotations

import os
import threading
import time

import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin

from conftest_bag import EEG, IMAGE, STRING, eeg_chunk, image, string, write_rosbags_bag
from mindgrasp_bag import BagError, BagReader, BagWriter, Player, Recorder
from mindgrasp_bag.player import parse_remaps

T0 = 1_750_000_000_000_000_000
MS = 1_000_000


def _record(path, messages):
    """Record ``(topic, type, t_ns, data)`` through the recorder core (as the node does)."""
    recorder = Recorder(BagWriter(path))
    recorder.start()
    for topic, msgtype in dict.fromkeys((m[0], m[1]) for m in messages):
        recorder.add_topic(topic, msgtype)
    for topic, _, stamp, data in messages:
        recorder.push(topic, data, stamp)
    recorder.stop()
    return path


def _session(n=30):
    """EEG every 20 ms and an image every 33 ms, with an irregular gap in the middle."""
    out = [('/eeg/raw', EEG, T0 + k * 20 * MS + (150 * MS if k > 15 else 0), eeg_chunk(25 * k))
           for k in range(n)]
    out += [('/camera/color/image_raw', IMAGE, T0 + 5 * MS + k * 33 * MS, image(k))
            for k in range(n // 2)]
    return sorted(out, key=lambda m: m[2])


def _realtime_available() -> bool:
    try:
        policy, param = os.sched_getscheduler(0), os.sched_getparam(0)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
        os.sched_setscheduler(0, policy, param)
    except (AttributeError, OSError):
        return False
    return True


#: Real-time priority of the playback thread where allowed (root); normal scheduling on a loaded
#: 2-core machine wakes a sleeping thread up to ~8 ms late, which the 5 ms check cannot absorb.
PRIORITY = 20 if _realtime_available() else 0


def _check_timing(got, stamps, rate=1.0) -> None:
    """Relative publication times: 90 % within 5 ms of the bag's, none off by 50 ms.

    A single late wake-up (another process, even with real-time priority on a busy 2-core
    machine) is not a player defect; the strict figures are `python benchmarks/recorder.py`'s."""
    errors = _timing_errors_ms(got, stamps, rate)
    assert np.percentile(errors, 90) < 5.0 and errors.max() < 50.0, errors


def _play(bag, **kwargs):
    got = []
    clock = []
    with BagReader(bag) as reader:
        player = Player(reader, **{k: v for k, v in kwargs.items() if k != 'clock_hz'})
        stats = player.run(lambda topic, data: got.append((topic, data, time.monotonic_ns())),
                           publish_clock=clock.append if 'clock_hz' in kwargs else None,
                           clock_hz=kwargs.get('clock_hz', 40.0), max_loops=2,
                           priority=PRIORITY)
    return got, clock, stats, player


def _timing_errors_ms(got, stamps, rate=1.0):
    wall = np.array([g[2] for g in got], dtype=np.int64)
    bag = np.array(stamps, dtype=np.int64)
    return np.abs((wall - wall[0]) - (bag - bag[0]) / rate) / 1e6


def test_record_play_round_trip_identical_bytes_and_timing(tmp_path):
    messages = _session()
    bag = _record(tmp_path / 'bag', messages)
    got, _, stats, _ = _play(bag)
    assert stats.notes == []
    assert [(t, d) for t, d, _ in got] == [(t, d) for t, _, _, d in messages]
    _check_timing(got, [m[2] for m in messages])
    assert stats.published == {'/eeg/raw': 30, '/camera/color/image_raw': 15}


def test_rate_and_start_offset(tmp_path):
    messages = _session()
    bag = _record(tmp_path / 'bag', messages)
    got, _, _, _ = _play(bag, rate=2.0, start_offset=0.2)
    kept = [m for m in messages if m[2] >= T0 + 200 * MS]
    assert [d for _, d, _ in got] == [m[3] for m in kept]
    _check_timing(got, [m[2] for m in kept], rate=2.0)
    duration = (got[-1][2] - got[0][2]) / 1e9
    assert duration == pytest.approx((kept[-1][2] - kept[0][2]) / 2e9, abs=0.005)


def test_topic_filter_regex_exclude_remap_and_loop(tmp_path):
    messages = _session(10)
    bag = _record(tmp_path / 'bag', messages)
    got, _, _, _ = _play(bag, topics=['/eeg/raw'], remap={'/eeg/raw': '/eeg/replayed'},
                         rate=10.0)
    assert {t for t, _, _ in got} == {'/eeg/replayed'} and len(got) == 10
    got, _, _, _ = _play(bag, regex='^/camera', rate=10.0)
    assert {t for t, _, _ in got} == {'/camera/color/image_raw'}
    got, _, _, _ = _play(bag, exclude_regex='image', rate=10.0)
    assert {t for t, _, _ in got} == {'/eeg/raw'}
    got, _, stats, _ = _play(bag, loop=True, rate=10.0)
    assert stats.loops == 2 and len(got) == 2 * len(messages)
    assert [d for _, d, _ in got[:len(messages)]] == [d for _, d, _ in got[len(messages):]]


def test_clock_publishes_bag_time(tmp_path):
    bag = _record(tmp_path / 'bag', _session())
    _, clock, _, _ = _play(bag, clock_hz=100.0)
    assert len(clock) > 40                      # ~0.75 s at 100 Hz
    assert clock == sorted(clock)
    assert T0 <= clock[0] < T0 + 20 * MS
    assert clock[-1] <= T0 + 760 * MS


def test_stop_event_ends_playback(tmp_path):
    bag = _record(tmp_path / 'bag', _session())
    stop = threading.Event()
    got = []
    with BagReader(bag) as reader:
        player = Player(reader, loop=True)
        threading.Timer(0.2, stop.set).start()
        stats = player.run(lambda t, d: got.append(t), stop=stop)
    assert stats.stopped and 0 < len(got) < 45


def test_rosbags_written_bags_play_sqlite3_and_mcap(tmp_path):
    messages = [('/chatter', STRING, T0 + k * 25 * MS, string(f'hello {k}')) for k in range(20)]
    for storage in (StoragePlugin.SQLITE3, StoragePlugin.MCAP):
        bag = write_rosbags_bag(tmp_path / storage.name, messages, storage)
        got, _, _, _ = _play(bag)
        assert [d for _, d, _ in got] == [m[3] for m in messages]
        _check_timing(got, [m[2] for m in messages])


def test_unknown_types_are_skipped_and_named(tmp_path):
    foo_def = 'int32 value\nstring note\n'
    bogus_hash = 'RIHS01_' + '0' * 64
    messages = [('/chatter', STRING, T0 + k * MS, string(f'hi {k}')) for k in range(5)]
    messages += [('/foo', 'foo_msgs/msg/Bar', T0 + k * MS + 1, b'\x00\x01\x00\x00' + bytes(12))
                 for k in range(5)]
    bag = write_rosbags_bag(tmp_path / 'bag', messages, extra_types={
        'foo_msgs/msg/Bar': (foo_def, bogus_hash)})
    got, _, stats, player = _play(bag, rate=10.0)
    assert {t for t, _, _ in got} == {'/chatter'}
    assert 'foo_msgs/msg/Bar is unknown here' in stats.skipped['/foo']
    assert any(line.startswith('Skipping /foo: its message type foo_msgs/msg/Bar')
               for line in player.skipped_report())


def test_changed_definition_is_skipped(tmp_path):
    messages = [('/a', STRING, T0, string('x')), ('/b', STRING, T0 + MS, string('y'))]
    bag = write_rosbags_bag(tmp_path / 'bag', messages[:1])
    other = write_rosbags_bag(tmp_path / 'other', messages[1:], extra_types={
        STRING: ('string data\nint32 extra\n', 'RIHS01_' + '1' * 64)})
    got, _, stats, _ = _play(other)
    assert got == [] and 'was recorded with another definition' in stats.skipped['/b']
    got, _, stats, _ = _play(bag)
    assert len(got) == 1 and stats.skipped == {}


def test_bad_options_give_clear_errors(tmp_path):
    bag = _record(tmp_path / 'bag', _session(2))
    with BagReader(bag) as reader:
        with pytest.raises(BagError, match='rate must be > 0'):
            Player(reader, rate=0.0)
        with pytest.raises(BagError, match=r'has no topic /nope; its topics are: /camera'):
            Player(reader, topics=['/nope'])
        with pytest.raises(BagError, match='regular expression is not valid'):
            Player(reader, regex='(')
        with pytest.raises(BagError, match='start offset must be >= 0'):
            Player(reader, start_offset=-1)
    with pytest.raises(BagError, match=r"remap 'eeg' is not valid; write it as /from:=/to"):
        parse_remaps(['eeg'])
    assert parse_remaps(['/a:=/b']) == {'/a': '/b'}
