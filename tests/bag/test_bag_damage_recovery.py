"""A damaged chunk costs only that chunk, in every tool (issue 42, item 1).

A bag recorded by the real recorder node (a separate process, over DDS, from a publisher process)
gets 4096 seeded random bytes written over it at 1/3, 1/2 and 2/3 of its file, or across the
chunk header nearest to each of those points (what stopped the old scan there: the record framing
itself is broken). Every reader then skips the damage and reads every intact chunk after it:
``bag info``, the reader, ``bag play``, the EEG export and the classifier's bag loader read the
same >= 95 % of the messages; ``bag reindex`` keeps all of them, keeps the original beside the
repaired file and says how many were lost and why.
"""

from __future__ import annotations

import random
import re
import subprocess
import sys
import uuid
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from test_bag_nodes import _start, _stop

from conftest_bag import PUBLISHER, mindgrasp_cli
from mindgrasp_bag import BagReader
from mindgrasp_bag.damage import assess_bag

pytestmark = pytest.mark.slow

HERE = Path(__file__).parents[1]  # tests/: conftest_bag, for the child processes
N_EEG = 150                       # EEG chunks at 10 Hz (15 s), and a String every 130 ms
DAMAGE = 4096                     # bytes overwritten at each place


@pytest.fixture(scope='module')
def recorded(tmp_path_factory: pytest.TempPathFactory) -> tuple[str, Path]:
    """A bag of a publisher process recorded by the recorder node, small chunks (one or two
    messages each, as a long demo's bag has hundreds of chunks)."""
    prefix = f'/bagdmg_{uuid.uuid4().hex[:8]}'
    bag = tmp_path_factory.mktemp('recovery') / 'run' / 'bag'
    recorder, rec_out = _start([
        sys.executable, '-m', 'mindgrasp_bag.recorder_node', '--ros-args',
        '-p', f'output:={bag}', '-p', f'regex:="^{prefix}/"', '-p', 'discovery_period:=0.2',
        '-p', 'flush_interval:=0.05', '-p', 'chunk_size:=4000'])
    publisher = None
    try:
        assert rec_out.wait_for('Recording to', 60), rec_out.lines
        publisher, pub_out = _start([sys.executable, '-c', PUBLISHER, str(HERE), prefix,
                                     str(N_EEG)])
        assert pub_out.wait_for('done', 120), pub_out.lines + rec_out.lines
        assert publisher.wait(30) == 0, pub_out.lines
    finally:
        if publisher is not None and publisher.poll() is None:
            _stop(publisher)
        code = _stop(recorder)
        rec_out.thread.join(30)
    assert code == 0, rec_out.lines
    return prefix, bag


def _damage(bag: Path, where: str) -> list[int]:
    """Overwrite DAMAGE seeded random bytes at 1/3, 1/2, 2/3 of the file ('thirds'), or
    centred on the chunk header nearest to each ('headers'); the offsets written."""
    path = bag / 'bag_0.mcap'
    with path.open('rb') as f:
        starts = [c.chunk_start_offset for c in make_reader(f).get_summary().chunk_indexes]
    data = bytearray(path.read_bytes())
    rng = random.Random(42)
    offsets = []
    for fraction in (1 / 3, 1 / 2, 2 / 3):
        at = int(len(data) * fraction)
        if where == 'headers':
            at = min(starts, key=lambda s: abs(s - at)) - DAMAGE // 2
        data[at:at + DAMAGE] = rng.randbytes(DAMAGE)
        offsets.append(at)
    path.write_bytes(bytes(data))
    return offsets


@pytest.fixture(params=['thirds', 'headers'])
def damaged(request: pytest.FixtureRequest, recorded: tuple[str, Path],
            tmp_path: Path) -> tuple[str, Path, int, int]:
    """A copy of the recorded run, damaged; (prefix, run, recorded count, readable count)."""
    prefix, bag = recorded
    run = tmp_path / 'run'
    subprocess.run(['cp', '-a', str(bag.parent), str(run)], check=True)
    with BagReader(run / 'bag') as reader:
        recorded_count = reader.message_count
        chunks = len(make_reader((run / 'bag' / 'bag_0.mcap').open('rb')).get_summary()
                     .chunk_indexes)
    assert chunks >= 100, chunks              # as a demo's bag: many chunks
    _damage(run / 'bag', request.param)
    damage = assess_bag(run / 'bag')
    assert damage.damaged and damage.expected_messages == recorded_count
    if request.param == 'headers':            # the framing itself was broken, and read past
        assert sum('are not MCAP records' in p for p in damage.problems) >= 1, damage.problems
    return prefix, run, recorded_count, damage.readable_messages


def test_every_reader_reads_at_least_95_percent_of_the_messages(damaged) -> None:
    prefix, run, recorded_count, readable = damaged
    assert readable >= 0.95 * recorded_count, (readable, recorded_count)
    # bag info: the counts, every damage with its byte offset; exit 1 without --allow-damaged
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 1, info.stdout + info.stderr
    assert f'{readable} message(s) readable of {recorded_count} recorded' in info.stdout
    assert re.search(r'Damage: bag_0\.mcap: .*byte \d+', info.stdout), info.stdout
    as_yaml = mindgrasp_cli('bag', 'info', '--yaml', '--allow-damaged', str(run))
    assert as_yaml.returncode == 0, as_yaml.stderr
    counts = yaml.safe_load(as_yaml.stdout)['damage']
    assert counts['readable_messages'] == readable and counts['skipped_bytes'] >= 3 * DAMAGE // 2
    # the reader: the same messages, in time order, without repeats
    with BagReader(run / 'bag') as reader:
        got = list(reader.messages())
    times = [t for _, t, _ in got]
    assert len(got) == readable and times == sorted(times)
    assert len({(topic, t, bytes(d)) for topic, t, d in got}) == len(got)
    # bag play publishes every readable message
    play = mindgrasp_cli('bag', 'play', str(run), '--delay', '0', '--rate', '20',
                         '--no-progress', '--allow-damaged')
    assert play.returncode == 0, play.stdout + play.stderr
    assert f'Published {readable} message(s)' in play.stdout + play.stderr
    # the EEG export and the classifier's loader: >= 95 % of the samples, the rest NaN
    from mindgrasp_classifier.data import load_bag
    from mindgrasp_eeg.export import read_session

    eeg = [d for topic, _, d in got if topic == f'{prefix}/eeg']
    recording = read_session(run, f'{prefix}/eeg')
    assert recording.n_missing <= 0.05 * len(recording.data)
    assert len(recording.data) - recording.n_missing == 25 * len(eeg)
    training = load_bag(run, f'{prefix}/eeg', labels='intent', intent_topic=f'{prefix}/chatter')
    present = int(np.isfinite(training.data[:, 0]).sum())
    assert present == 25 * len(eeg) >= 0.95 * 25 * N_EEG


def test_reindex_keeps_every_readable_message_and_the_original(damaged) -> None:
    _, run, recorded_count, readable = damaged
    original = (run / 'bag' / 'bag_0.mcap').read_bytes()
    done = mindgrasp_cli('bag', 'reindex', str(run))
    assert done.returncode == 0, done.stdout + done.stderr
    assert (f'bag_0.mcap has been rewritten with its summary: {readable} message(s) kept, '
            f'{recorded_count - readable} of {recorded_count} recorded lost; the original is '
            'kept as bag_0.mcap.damaged.') in done.stdout, done.stdout
    assert re.search(r'lost: bag_0\.mcap: .*byte \d+', done.stdout), done.stdout  # and why
    assert (run / 'bag' / 'bag_0.mcap.damaged').read_bytes() == original   # nothing deleted
    with BagReader(run / 'bag') as reader:
        assert reader.message_count == sum(1 for _ in reader.messages()) == readable
        assert any('bag_0.mcap.damaged' in n for n in reader.notes), reader.notes
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 0, info.stdout + info.stderr     # the repaired bag is sound
    assert 'bag_0.mcap.damaged: the original' in info.stdout
    # a second reindex has nothing to repair and keeps the backup
    again = mindgrasp_cli('bag', 'reindex', str(run))
    assert again.returncode == 0 and 'rewritten' not in again.stdout, again.stdout
    assert (run / 'bag' / 'bag_0.mcap.damaged').read_bytes() == original
