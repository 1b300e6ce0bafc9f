"""``mindgrasp experiment`` on a disk that fills up during the run (issue 31, item 1): the
experiment's real nodes in lock-step, its run directory on a real tmpfs with 64 KiB free (the
parameter files fit, the report and plots do not). Nothing recorded is lost: every record is in
the run directory or in the fallback folder the one-line warning names, no file is truncated, no
traceback, and the exit code says that the run directory is incomplete."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from mindgrasp_common.safe_files import fallback_folder
from mindgrasp_experiments.records import read_records
from mindgrasp_testing import small_tmpfs

pytestmark = pytest.mark.slow

FREE = 64 << 10     # bytes left on the disk when the experiment starts


@pytest.fixture
def nearly_full_disk(tmp_path):
    with small_tmpfs(tmp_path / 'small', '1M') as mount:
        stat = os.statvfs(mount)
        (mount / 'filler').write_bytes(b'\0' * (stat.f_bavail * stat.f_frsize - FREE))
        yield mount


@pytest.mark.timeout(900)
def test_experiment_on_a_filling_disk_loses_no_record(nearly_full_disk, tmp_path):
    out, state = nearly_full_disk / 'run', tmp_path / 'state'
    done = subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'experiment', 'set-locations', '--trials',
         '2', '--subject', 'oracle', '--seed', '2', '--out', str(out), '--no-progress'],
        capture_output=True, text=True, timeout=800, check=False,
        env=dict(os.environ, XDG_STATE_HOME=str(state)))
    assert 'Traceback' not in done.stderr, done.stderr[-4000:]
    assert done.returncode == 1, done.stdout[-2000:] + done.stderr[-2000:]
    copy = fallback_folder(out, state / 'mindgrasp' / 'unwritten')
    faults = [line for line in done.stderr.splitlines() if 'Cannot write the' in line]
    assert faults and all(str(copy) in line and 'No space left on device' in line
                          for line in faults), done.stderr
    # every trial's record is complete somewhere: the run directory or the fallback copy
    kept = read_records(copy) if (copy / 'records.csv').exists() else read_records(out)
    assert [r.trial for r in kept] == [1, 2]
    assert (copy / 'report.md').exists()
    for path in out.rglob('*'):
        assert not path.is_file() or path.stat().st_size > 0, path    # nothing truncated
