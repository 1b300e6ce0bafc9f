"""One damage policy in every bag tool (issue 31, item 2): on a bag cut in half or with damaged
chunks, ``bag info`` and ``bag play`` read what can be read, say what was skipped, count it, and
exit 1 unless ``--allow-damaged``; read-only tools write nothing; a missing bag path exits 2 (as
``ros2 bag info``, whose path argument fails argparse's check)."""

from __future__ import annotations

import contextlib
import re
from pathlib import Path

import pytest
import yaml

from conftest_bag import cut_in_half, damage_chunks, mindgrasp_cli, run_with_bag
from mindgrasp_bag import BagReader
from mindgrasp_bag.damage import assess_bag
from mindgrasp_testing import small_tmpfs

N = 30          # messages per topic of run_with_bag; 2 topics


def _files(run: Path) -> dict[str, bytes]:
    return {str(p.relative_to(run)): p.read_bytes() for p in sorted(run.rglob('*'))
            if p.is_file()}


def test_bag_cut_in_half_reports_readable_and_recorded_counts_and_writes_nothing(tmp_path):
    run = run_with_bag(tmp_path)
    cut_in_half(run / 'bag' / 'bag_0.mcap')
    with BagReader(run / 'bag') as reader:
        readable = sum(1 for _ in reader.messages())
    assert 0 < readable < 2 * N
    before = _files(run)
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 1, info.stdout + info.stderr
    assert re.search(rf'Readable: +{readable} message\(s\) readable of {2 * N} recorded '
                     rf'\({2 * N - readable} lost\)', info.stdout), info.stdout
    assert 'cut off' in info.stdout
    as_yaml = mindgrasp_cli('bag', 'info', '--yaml', '--allow-damaged', str(run))
    assert as_yaml.returncode == 0, as_yaml.stderr
    damage = yaml.safe_load(as_yaml.stdout)['damage']
    assert damage['expected_messages'] == 2 * N and damage['readable_messages'] == readable
    assert damage['lost_messages'] == 2 * N - readable and damage['cut_files'] == 1
    # the messages after the cut span about half of the 2.9 s recording
    assert 1.0 < damage['lost_span_s'] < 2.0, damage
    assert _files(run) == before          # read-only: not even metadata.yaml is rewritten


# zstd: what runs record by default; a damaged compressed chunk fails to decompress before its
# CRC is checked
@pytest.mark.parametrize('compression', ['none', 'zstd', 'lz4'])
def test_three_damaged_chunks_are_skipped_counted_and_the_rest_is_played(tmp_path, compression):
    run = run_with_bag(tmp_path, compression=compression)
    offsets = damage_chunks(run / 'bag' / 'bag_0.mcap')
    damage = assess_bag(run / 'bag')
    assert damage.skipped_records == 3 and damage.damaged
    assert 0 < damage.readable_messages < 2 * N == damage.expected_messages
    assert len(damage.lost_spans) == 3 and damage.lost_span_ns > 0
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 1
    for offset in offsets:
        assert f'record at byte {offset} (opcode 0x06' in info.stdout, info.stdout
    play = mindgrasp_cli('bag', 'play', str(run), '--delay', '0', '--rate', '10', '--no-progress')
    out = play.stdout + play.stderr
    assert play.returncode == 1, out
    # everything readable was played, not only what came before the first damaged chunk
    assert f'Published {damage.readable_messages} message(s)' in out, out
    assert f'{damage.readable_messages} message(s) readable of {2 * N} recorded' in out
    assert '--allow-damaged' in out and 'Traceback' not in out
    allowed = mindgrasp_cli('bag', 'play', str(run), '--delay', '0', '--rate', '10',
                         '--no-progress', '--allow-damaged')
    assert allowed.returncode == 0, allowed.stdout + allowed.stderr
    assert f'Published {damage.readable_messages} message(s)' in allowed.stdout + allowed.stderr


def test_a_sound_bag_reports_no_damage(tmp_path):
    run = run_with_bag(tmp_path)
    damage = assess_bag(run / 'bag')
    assert not damage.damaged and damage.readable_messages == damage.expected_messages == 2 * N
    assert damage.lines() == []


def test_a_missing_bag_path_exits_2_with_one_line(tmp_path):
    for verb in ('info', 'reindex', 'play'):
        done = mindgrasp_cli('bag', verb, str(tmp_path / 'nope'))
        assert done.returncode == 2, (verb, done.stderr)
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and 'does not exist' in lines[0], (verb, done.stderr)


def test_reindex_on_a_full_disk_leaves_the_bag_as_it_was(tmp_path):
    with small_tmpfs(tmp_path / 'disk', '512k') as disk:
        run = run_with_bag(disk)
        cut_in_half(run / 'bag' / 'bag_0.mcap')
        with (disk / 'filler').open('wb', buffering=0) as f, \
                contextlib.suppress(OSError):      # until the disk is full
            while True:
                f.write(b'\0' * 4096)
        before = _files(run)
        done = mindgrasp_cli('bag', 'reindex', str(run))
        assert done.returncode == 1, done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and 'No space left on device' in lines[0], done.stderr
        assert _files(run) == before          # no partial copy, the original untouched


def test_the_reader_reads_on_past_damaged_chunks_in_order_without_repeats(tmp_path):
    run = run_with_bag(tmp_path)
    offsets = damage_chunks(run / 'bag' / 'bag_0.mcap')
    with BagReader(run / 'bag') as reader:
        got = list(reader.messages())
        # read through the index, each damaged chunk skipped and said with its offset and count
        skipped = [n for n in reader.notes if 'is corrupt' in n]
        assert [int(re.search(r'chunk at byte (\d+)', n)[1]) for n in skipped] == offsets
        assert all(re.search(r'\d+ message\(s\) lost', n) for n in skipped), skipped
    times = [t for _, t, _ in got]
    assert times == sorted(times) and len(set(times)) == len(times)
    assert len(got) == assess_bag(run / 'bag').readable_messages
    assert got[-1][1] == 1_000_000_000 + (N - 1) * 100_000_000 + 1     # up to the end
