"""Files that survive a full disk: atomic writes, and records kept until they can be written.

    writer = DeferredWriter(run_dir)
    for line in writer.write(run_dir / 'trials', 'trial records', write_fn):
        logger.warning(line)          # one line per fault and per recovery, never a traceback
    for line in writer.close():       # last retry; what still fails stays in the fallback copy
        logger.warning(line)

Why: a run directory on a full disk (or a quota, a read-only remount) must lose only what cannot
be written. A plain ``open('w')`` truncates the old file before the write fails, so a full disk
used to leave ``records.csv`` and ``summary.yaml`` at 0 bytes. Here every file is written to a
temporary name and renamed over the old one (as rosbag2 and atomic writers do), so a file is
either the old one or the new one; and what cannot be written is kept in memory, retried at
every later write, and copied to a fallback directory the log names
(``$XDG_STATE_HOME/mindgrasp/unwritten/<run path>``, else
``/tmp/mindgrasp-unwritten/<run path>``, the path's slashes as underscores).
"""

from __future__ import annotations

import contextlib
import errno
import os
from collections.abc import Callable
from pathlib import Path

__all__ = ['DISK_ERRNOS', 'DeferredWriter', 'fallback_folder', 'fallback_root', 'write_atomic']

#: errors of the disk rather than of the program: keep the data and go on
DISK_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EIO, errno.EFBIG,
                         errno.EACCES, errno.EPERM})


def write_atomic(path: Path, write: Callable[[Path], object]) -> Path:
    """Write ``path`` through ``write(tmp)`` and a rename, so it is never left half written.

    Parameters
    ----------
    path
        The file to (re)place.
    write
        Writes the whole content to the path it is given (a temporary file beside
        ``path``).

    Raises
    ------
    OSError
        The write or the rename failed; ``path`` is unchanged and the temporary file
        is removed.
    """
    path = Path(path)
    tmp = path.with_name(f'.{path.name}.tmp')
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            tmp.unlink()
        raise
    return path


def fallback_root() -> Path:
    """Where files go when their own directory cannot take them (see the module docstring)."""
    state = os.environ.get('XDG_STATE_HOME', '')
    if state:
        return Path(state) / 'mindgrasp' / 'unwritten'
    return Path('/tmp') / 'mindgrasp-unwritten'


def fallback_folder(run_dir: Path, root: Path | None = None) -> Path:
    """The fallback folder of ``run_dir``: named after its whole path (two runs both called
    ``run`` must not share one), under ``root`` (default :func:`fallback_root`)."""
    name = str(Path(run_dir).absolute()).strip('/').replace('/', '_') or 'root'
    return (root if root is not None else fallback_root()) / name


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


class DeferredWriter:
    """Writes the files of one run directory; on a disk fault keeps them and retries.

    A write is a directory, a name for the log ("trial records") and a function that writes the
    files into the directory it is given (atomically, e.g. with :func:`write_atomic`). A later
    write with the same directory and name replaces a pending one (records grow, the newest
    holds all).

    Parameters
    ----------
    run_dir
        The run directory; names the fallback folder and relative paths in it.
    fallback
        Fallback root (default :func:`fallback_root`).
    """

    def __init__(self, run_dir: Path | None = None, fallback: Path | None = None) -> None:
        self.run_dir = Path(run_dir) if run_dir is not None else None
        self.fallback = Path(fallback) if fallback is not None else fallback_root()
        #: (directory, name) -> the write function not yet done in its own directory
        self.pending: dict[tuple[Path, str], Callable[[Path], object]] = {}
        self.written_to_fallback: dict[tuple[Path, str], Path] = {}
        self._reported: set[tuple[Path, str]] = set()   # faults logged already

    def _fallback_dir(self, directory: Path) -> Path:
        run = self.run_dir if self.run_dir is not None else directory
        if directory == run or run in directory.parents:
            return fallback_folder(run, self.fallback) / directory.relative_to(run)
        return fallback_folder(directory, self.fallback)

    def write(self, directory: Path, what: str, write: Callable[[Path], object]) -> list[str]:
        """Write now, or keep for later; returns log lines (none when all went well).

        Pending writes of other names are retried first, so they land when space returns.
        """
        key = (Path(directory), what)
        self.pending.pop(key, None)      # superseded by this write
        lines = self.retry()
        self.pending[key] = write
        lines += self._attempt(key, first=True)
        return lines

    def retry(self) -> list[str]:
        """Retry every pending write in its own directory; lines for those that succeeded."""
        lines: list[str] = []
        for key in list(self.pending):
            lines += self._attempt(key, first=False)
        return lines

    def close(self) -> list[str]:
        """A last retry; a line for each write still not in its own directory."""
        lines = self.retry()
        for (directory, what), _ in self.pending.items():
            copy = self.written_to_fallback.get((directory, what))
            where = f'the copy in {copy} is complete' if copy is not None else \
                'no copy could be written anywhere'
            lines.append(f'The {what} could not be written to {directory} before the end (disk '
                         f'full or not writable); {where}: copy it back when there is space.')
        return lines

    def _attempt(self, key: tuple[Path, str], *, first: bool) -> list[str]:
        directory, what = key
        write = self.pending[key]
        try:
            directory.mkdir(parents=True, exist_ok=True)
            write(directory)
        except OSError as exc:
            if exc.errno not in DISK_ERRNOS:
                raise
            # one line per fault: a retry that fails again says nothing new
            line = self._keep(key, write, exc) if first else None
            return [line] if line else []
        del self.pending[key]
        copy = self.written_to_fallback.pop(key, None)
        if key not in self._reported:
            return []
        self._reported.discard(key)
        spare = f' (the copy in {copy} is no longer needed)' if copy is not None else ''
        return [f'The {what} are written to {directory} now that it takes data again{spare}.']

    def _keep(self, key: tuple[Path, str], write: Callable[[Path], object],
              exc: OSError) -> str | None:
        """Copy to the fallback; the line to log (None when this fault was reported already)."""
        directory, what = key
        reported = key in self._reported
        self._reported.add(key)
        copy_dir = self._fallback_dir(directory)
        try:
            copy_dir.mkdir(parents=True, exist_ok=True)
            write(copy_dir)
        except OSError as copy_exc:
            self.written_to_fallback.pop(key, None)
            if reported:
                return None
            return (f'Cannot write the {what} to {directory} ({_reason(exc)}) nor to the '
                    f'fallback {copy_dir} ({_reason(copy_exc)}); they are kept in memory and '
                    'written when space returns: free space on either disk.')
        self.written_to_fallback[key] = copy_dir
        if reported:
            return None
        return (f'Cannot write the {what} to {directory} ({_reason(exc)}); a complete copy is '
                f'in {copy_dir}, and they are kept in memory and written to {directory} if '
                'space returns.')
