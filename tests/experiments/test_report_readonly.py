"""``mindgrasp experiment report`` reads the records and never rewrites them; on a disk that
cannot take the report it says so in one line and the records are untouched (issue 31, item 1)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from mindgrasp_experiments.records import TrialRecord, read_records, write_records
from mindgrasp_testing import small_tmpfs


def _records() -> list[TrialRecord]:
    return [TrialRecord(trial=k, protocol='set_locations', subject='oracle', desired='red cube',
                        success=k % 2 == 0) for k in (1, 2, 3)]


def _report(run: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'experiment', 'report',
                           str(run)], capture_output=True, text=True, timeout=300, check=False)


def test_report_rebuild_leaves_the_record_files_alone(tmp_path):
    write_records(_records(), tmp_path)
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes())
              for p in tmp_path.glob('records.*')}
    done = _report(tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / 'report.md').exists()
    assert {p.name: (p.stat().st_mtime_ns, p.read_bytes())
            for p in tmp_path.glob('records.*')} == before


def test_report_on_a_read_only_disk_is_one_line_and_keeps_the_records(tmp_path):
    with small_tmpfs(tmp_path / 'ro', '4M') as mount:
        write_records(_records(), mount)
        subprocess.run(['mount', '-o', 'remount,ro', str(mount)], check=True)
        done = _report(mount)
        assert done.returncode == 1, done.stderr
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and 'cannot write the report into' in lines[0], done.stderr
        assert 'Read-only file system' in lines[0] and 'records are unchanged' in lines[0]
        assert [r.trial for r in read_records(mount)] == [1, 2, 3]
