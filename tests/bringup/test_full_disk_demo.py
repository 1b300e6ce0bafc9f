"""A full disk costs only what cannot be written (issue 31, item 1), end to end: the demo runs
with its run directory on a 3 MB tmpfs (real processes, DDS, LSL, PyBullet, MCAP). Once the bag
holds a few chunks, the test keeps the disk full (a ballast file topped up until the launch ends),
so the disk is full when the trial ends however fast the machine is. The recorder stops when the
disk fills; the trial still ends and its record goes to the fallback folder the
log names; no file is left truncated; the recorder's count is what the bag holds; ``bag info``
reads the bag on the full disk without writing; no traceback anywhere."""

from __future__ import annotations

import contextlib
import re
import subprocess
import sys
import threading
import time
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import kill_group, launch_env, start_launch

from mindgrasp_bag import BagReader
from mindgrasp_common.safe_files import fallback_folder
from mindgrasp_experiments.records import read_records
from mindgrasp_testing import small_tmpfs

pytestmark = pytest.mark.slow
CHUNK = 32768        # B, the recorder's MCAP chunk size in this test


@pytest.fixture
def small_disk(tmp_path):
    with small_tmpfs(tmp_path / 'small', '3M') as mount:
        yield mount


def _fill(ballast: Path) -> None:
    """Append to ``ballast`` until the file system says it is full."""
    with contextlib.suppress(OSError), ballast.open('ab') as out:
        while True:
            out.write(b'\0' * 16384)
            out.flush()


@contextlib.contextmanager
def _kept_full(disk: Path, started: Path, proc: subprocess.Popen) -> Iterator[None]:
    """Once the bag in ``started`` holds a few chunks, keep ``disk`` full until the block ends
    (space the run frees, e.g. a cut chunk dropped, is taken again at once)."""
    done = threading.Event()

    def keep() -> None:
        while not done.is_set() and proc.poll() is None:
            if any(p.stat().st_size > 3 * CHUNK for p in started.glob('*.mcap')):
                _fill(disk / 'ballast')
            time.sleep(0.05)

    thread = threading.Thread(target=keep, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join(timeout=30)


@pytest.mark.timeout(1200)
def test_demo_on_a_full_disk_keeps_every_record_and_tells_the_truth(small_disk, tmp_path):
    run_dir, state = small_disk / 'run', tmp_path / 'state'
    params = tmp_path / 'test_params.yaml'      # a deadline for the trial on a loaded machine
    params.write_text(yaml.safe_dump({     # small chunks: some are whole before the disk fills
        'trial_manager': {'ros__parameters': {'trial_timeout': 300.0}},
        'recorder': {'ros__parameters': {'chunk_size': CHUNK}}}), encoding='utf-8')
    proc = start_launch('demo', 'duration:=500', 'trials:=1', 'targets:=red cube',
                        'live_view_port:=0', f'eeg_stream:=mg-full-{uuid.uuid4().hex[:8]}',
                        '--sigint-timeout', '20', '--run-dir', str(run_dir),
                        MINDGRASP_PARAMS_FILES=str(params), XDG_STATE_HOME=str(state))
    try:
        with _kept_full(small_disk, run_dir / 'bag', proc):
            stdout, stderr = proc.communicate(timeout=900)
    finally:
        kill_group(proc)
    result = subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)
    out = result.stdout + result.stderr
    assert 'Traceback' not in out, out[-6000:]
    assert result.returncode == 1, out[-4000:]     # the recording failed: said, not hidden
    # the trial's record: in the fallback folder the log names, complete
    copy = fallback_folder(run_dir, state / 'mindgrasp' / 'unwritten')
    line = next(x for x in out.splitlines() if 'Cannot write the trial records' in x)
    assert str(copy / 'trials') in line and 'No space left on device' in line
    (record,) = read_records(copy / 'trials')
    assert record.desired == 'red cube'
    # nothing truncated: every file of the run directory is either absent or whole
    for name in ('summary.yaml', 'trials/records.csv', 'trials/records.parquet'):
        path = run_dir / name
        assert not path.exists() or path.stat().st_size > 0, name
    summary = run_dir / 'summary.yaml' if (run_dir / 'summary.yaml').exists() \
        else copy / 'summary.yaml'
    assert yaml.safe_load(summary.read_text())['exit_code'] == 1
    # the recorder's count is what can be recovered
    kept = re.search(r'(\d+) message\(s\) are on disk and recoverable', out)
    assert kept, out[-4000:]
    with BagReader(run_dir / 'bag') as reader:
        assert sum(1 for _ in reader.messages()) == int(kept.group(1)) > 0
    # bag info on the full disk: reads, reports the cut file, writes nothing
    before = sorted(p.name for p in (run_dir / 'bag').iterdir())
    info = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'info', str(run_dir)],
                          capture_output=True, text=True, env=launch_env(), timeout=300)
    assert info.returncode == 1 and 'cut off' in info.stdout, info.stdout + info.stderr
    assert f'Readable:          {kept.group(1)} message(s) readable' in info.stdout
    assert 'Traceback' not in info.stderr
    assert sorted(p.name for p in (run_dir / 'bag').iterdir()) == before
