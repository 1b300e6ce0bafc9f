"""Atomic writes and records kept through a full disk (ENOSPC injected at the file layer)."""

from __future__ import annotations

import errno
from pathlib import Path

import pytest

from mindgrasp_common.safe_files import DeferredWriter, fallback_folder, write_atomic


class Disk:
    """A disk that can be made full: writes into ``full_dirs`` fail with ENOSPC after a byte."""

    def __init__(self) -> None:
        self.full_dirs: set[Path] = set()

    def writer(self, text: str):
        def write(folder: Path) -> None:
            def body(path: Path) -> None:
                with path.open('w', encoding='utf-8') as f:
                    f.write(text[:1])       # a real full disk takes a little, then refuses
                    if folder in self.full_dirs:
                        raise OSError(errno.ENOSPC, 'No space left on device')
                    f.write(text[1:])
            write_atomic(folder / 'records.csv', body)
        return write


def test_write_atomic_leaves_the_old_file_when_the_disk_is_full(tmp_path):
    target = tmp_path / 'records.csv'
    target.write_text('trial 1\n')

    def full(path: Path) -> None:
        path.write_text('trial 1\ntr')
        raise OSError(errno.ENOSPC, 'No space left on device')

    with pytest.raises(OSError, match='No space left'):
        write_atomic(target, full)
    assert target.read_text() == 'trial 1\n'            # never truncated
    assert sorted(p.name for p in tmp_path.iterdir()) == ['records.csv']   # no temp file left


def test_records_go_to_the_fallback_then_home_when_space_returns(tmp_path):
    run, fallback = tmp_path / 'run', tmp_path / 'state'
    trials = run / 'trials'
    disk = Disk()
    files = DeferredWriter(run, fallback=fallback)
    assert files.write(trials, 'trial records', disk.writer('a,b\n1,2\n')) == []
    disk.full_dirs.add(trials)
    lines = files.write(trials, 'trial records', disk.writer('a,b\n1,2\n3,4\n'))
    assert len(lines) == 1 and 'Cannot write the trial records' in lines[0]
    copy = fallback_folder(run, fallback) / 'trials'
    assert 'No space left on device' in lines[0] and str(copy) in lines[0]
    assert (trials / 'records.csv').read_text() == 'a,b\n1,2\n'    # old version intact
    assert (copy / 'records.csv').read_text() == 'a,b\n1,2\n3,4\n'
    # still full: the next trial's write updates the copy and says nothing new
    assert files.write(trials, 'trial records', disk.writer('a,b\n1,2\n3,4\n5,6\n')) == []
    assert (copy / 'records.csv').read_text().endswith('5,6\n')
    disk.full_dirs.clear()                                  # space returns
    lines = files.close()
    assert len(lines) == 1 and 'written to' in lines[0] and 'now that it takes data' in lines[0]
    assert (trials / 'records.csv').read_text() == 'a,b\n1,2\n3,4\n5,6\n'
    assert files.pending == {}


def test_a_fault_that_lasts_to_the_end_is_one_line_naming_the_copy(tmp_path):
    run, fallback = tmp_path / 'run', tmp_path / 'state'
    disk = Disk()
    disk.full_dirs.add(run)
    files = DeferredWriter(run, fallback=fallback)
    assert len(files.write(run, 'run summary', disk.writer('exit_code: 0\n'))) == 1
    lines = files.close()
    copy = fallback_folder(run, fallback)
    assert len(lines) == 1 and str(copy) in lines[0] and 'complete' in lines[0]


def test_both_disks_full_keeps_the_records_in_memory(tmp_path):
    run, fallback = tmp_path / 'run', tmp_path / 'state'
    disk = Disk()
    disk.full_dirs |= {run, fallback_folder(run, fallback)}
    files = DeferredWriter(run, fallback=fallback)
    lines = files.write(run, 'trial records', disk.writer('a\n1\n'))
    assert len(lines) == 1 and 'nor to the fallback' in lines[0] and 'kept in memory' in lines[0]
    disk.full_dirs.clear()
    assert 'now that it takes data again' in files.retry()[0]
    assert (run / 'records.csv').read_text() == 'a\n1\n'


def test_an_error_that_is_not_the_disk_is_raised(tmp_path):
    def broken(folder: Path) -> None:
        raise OSError(errno.EISDIR, 'Is a directory')

    with pytest.raises(OSError, match='Is a directory'):
        DeferredWriter(tmp_path).write(tmp_path, 'trial records', broken)
