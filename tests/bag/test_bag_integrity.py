"""Bag integrity through real processes and real bags: ``bag reindex`` after a SIGKILLed
recorder, ``bag info`` reporting damage with its byte offset, run directories accepted by
``bag info`` and ``bag play`` (with progress and a summary line)."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
import time
import uuid
from pathlib import Path

import pytest
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader as RosbagsReader

from conftest_bag import (
    PUBLISHER,
    cli_env,
    mindgrasp_cli,
    run_with_bag,
)
from mindgrasp_bag.mcap_scan import read_mcap_contents

HERE = Path(__file__).parents[1]  # tests/: conftest_bag, for the child processes


def _plain_mcap_count(path: Path) -> int:
    """Messages as the mcap library's default reader sees them (it needs the summary)."""
    with path.open('rb') as f:
        return sum(1 for _ in make_reader(f).iter_messages())


@pytest.mark.slow
def test_reindex_makes_a_sigkilled_recording_readable_by_the_plain_mcap_reader(tmp_path):
    prefix = f'/reindex_{uuid.uuid4().hex[:8]}'
    run = tmp_path / 'run'
    bag = run / 'bag'
    recorder = subprocess.Popen(
        [sys.executable, '-m', 'mindgrasp_bag.recorder_node', '--ros-args',
         '-p', f'output:={bag}', '-p', f'regex:="^{prefix}/"', '-p', 'discovery_period:=0.2',
         '-p', 'flush_interval:=0.2'], env=cli_env(), stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL)
    publisher = subprocess.Popen([sys.executable, '-c', PUBLISHER, str(HERE), prefix, '200'],
                                 env=cli_env(), stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
    try:
        mcap = bag / 'bag_0.mcap'
        deadline = time.monotonic() + 90
        while time.monotonic() < deadline:
            if mcap.exists() and read_mcap_contents(mcap).message_count >= 20:
                break
            time.sleep(0.2)
        recorder.send_signal(signal.SIGKILL)     # mid-recording: no summary, no footer
        recorder.wait(10)
    finally:
        for proc in (publisher, recorder):
            if proc.poll() is None:
                proc.kill()
                proc.wait(10)
    recovered = read_mcap_contents(mcap).message_count
    assert recovered >= 20
    with pytest.raises(Exception):  # noqa: B017 - the library raises several types
        _plain_mcap_count(mcap)
    done = mindgrasp_cli('bag', 'reindex', str(run))
    assert done.returncode == 0, done.stdout + done.stderr
    assert 'bag_0.mcap has been rewritten with its summary' in done.stdout
    assert _plain_mcap_count(mcap) == recovered
    reader = RosbagsReader(bag)
    reader.open()
    assert reader.message_count == recovered
    reader.close()
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 0 and 'Damage' not in info.stdout, info.stdout + info.stderr


def test_bag_info_reports_a_bit_flip_with_the_chunk_offset(tmp_path):
    run = run_with_bag(tmp_path)
    path = run / 'bag' / 'bag_0.mcap'
    with path.open('rb') as f:
        chunks = make_reader(f).get_summary().chunk_indexes
    assert len(chunks) >= 3
    target = chunks[1]
    data = bytearray(path.read_bytes())
    data[target.chunk_start_offset + target.chunk_length - 40] ^= 0x04   # inside its records
    path.write_bytes(bytes(data))
    info = mindgrasp_cli('bag', 'info', str(run))
    assert info.returncode == 1
    damage = [line for line in info.stdout.splitlines() if line.startswith('Damage:')]
    assert len(damage) == 1, info.stdout
    assert f'record at byte {target.chunk_start_offset} (opcode 0x06' in damage[0]
    assert 'crc validation failed' in damage[0]
    # reindex keeps every other chunk
    done = mindgrasp_cli('bag', 'reindex', str(run / 'bag'))
    assert done.returncode == 0, done.stdout + done.stderr
    assert 0 < _plain_mcap_count(path) < 60


def test_bag_info_reports_garbage_after_a_valid_header(tmp_path):
    run = run_with_bag(tmp_path)
    path = run / 'bag' / 'bag_0.mcap'
    data = path.read_bytes()
    header_end = 8 + 9 + int.from_bytes(data[9:17], 'little')
    path.write_bytes(data[:header_end] + bytes(range(256)) * 8)
    (run / 'bag' / 'metadata.yaml').unlink()
    info = mindgrasp_cli('bag', 'info', str(run), '--no-rebuild')
    assert info.returncode == 1
    assert (f'Damage: bag_0.mcap: bytes at {header_end} are not an MCAP record (opcode 0x00)'
            in info.stdout), info.stdout


@pytest.mark.slow
def test_bag_info_and_play_accept_a_run_directory_and_play_shows_progress(tmp_path):
    run = run_with_bag(tmp_path, n=20)
    by_run, by_bag = mindgrasp_cli('bag', 'info', str(run)), mindgrasp_cli('bag', 'info',
                                                                      str(run / 'bag'))
    assert by_run.returncode == 0 and by_run.stdout == by_bag.stdout
    assert 'Count:      20' in by_run.stdout
    lines: list[str] = []
    proc = subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'play', str(run),
                             '--delay', '0.2'], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, env=cli_env())
    reader = threading.Thread(target=lambda: lines.extend(proc.stdout), daemon=True)
    reader.start()
    assert proc.wait(120) == 0
    reader.join(10)
    out = ''.join(lines)
    assert 'bag play:' in out and '40/40' in out        # tqdm progress
    last = out.rstrip().splitlines()[-1]
    assert re.search(r'Published 40 message\(s\) on 2 topic\(s\); worst lateness [\d.]+ ms\.$',
                     last), out
