"""Test helpers shared by every test folder (import as ``from mindgrasp_testing import ...``).

A module of its own, because ``from conftest import`` picks whichever conftest.py comes first on
sys.path when several test folders have one.
"""

from __future__ import annotations

import contextlib
import struct
import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_ros.node_process import NodeProcess

__all__ = ['NodeProcess', 'console_scripts', 'small_tmpfs', 'spin_until', 'write_xdf']


def spin_until(node: object, predicate: Callable[[], bool], timeout: float = 10.0,
               executor: object = None) -> bool:
    """Spin ``node`` until ``predicate()`` is true or ``timeout`` seconds pass."""
    from mindgrasp_ros import rclpy

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        if executor is not None:
            executor.spin_once(timeout_sec=0.05)
        else:
            rclpy.spin_once(node, timeout_sec=0.05)
    return predicate()


@contextlib.contextmanager
def small_tmpfs(path: Path, size: str) -> Iterator[Path]:
    """A real tmpfs of ``size`` (e.g. ``'3M'``) mounted at ``path`` for the block, to fill up;
    the test is skipped with the reason where mounting is not allowed (not root)."""
    path.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(['mount', '-t', 'tmpfs', '-o', f'size={size}', 'tmpfs', str(path)],
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        pytest.skip(f'cannot mount a {size} tmpfs to fill (needs root): {done.stderr.strip()}')
    try:
        yield path
    finally:
        subprocess.run(['umount', '-l', str(path)], check=False)


def root_setup():
    """The repository's setup.py as a module (its ``setup()`` call runs only as ``__main__``):
    the one reader of the packages' entry points, :func:`package_entry_points`."""
    import importlib.util

    spec = importlib.util.spec_from_file_location('mindgrasp_root_setup',
                                                  Path(__file__).resolve().parents[1] / 'setup.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def console_scripts(package_dir: Path) -> dict[str, str]:
    """``{executable: 'module:function'}`` of a package's setup.py (read, not executed)."""
    items = root_setup().package_entry_points(package_dir / 'setup.py').get('console_scripts', [])
    return dict((s.strip() for s in item.partition('=')[::2]) for item in items)


def _chunk(tag: int, content: bytes) -> bytes:
    body = struct.pack('<H', tag) + content
    return struct.pack('<BI', 4, len(body)) + body


def _varlen(n: int) -> bytes:
    return struct.pack('<BI', 4, n)


def write_xdf(path: Path, eeg_uv: np.ndarray, fs: float, t0: float,
              markers: list[tuple[float, str]], names: list[str], unit: str = 'microvolts') -> None:
    """XDF 1.0: file header, an EEG stream (float32) and a string marker stream."""
    chans = ''.join(f'<channel><label>{n}</label><unit>{unit}</unit><type>EEG</type></channel>'
                    for n in names)
    eeg_hdr = (f'<?xml version="1.0"?><info><name>amp</name><type>EEG</type>'
               f'<channel_count>{len(names)}</channel_count><nominal_srate>{fs}</nominal_srate>'
               f'<channel_format>float32</channel_format><created_at>0</created_at>'
               f'<desc><channels>{chans}</channels></desc></info>')
    mk_hdr = ('<?xml version="1.0"?><info><name>amp-markers</name><type>Markers</type>'
              '<channel_count>1</channel_count><nominal_srate>0</nominal_srate>'
              '<channel_format>string</channel_format><created_at>0</created_at></info>')
    out = b'XDF:' + _chunk(1, b'<?xml version="1.0"?><info><version>1.0</version></info>')
    out += _chunk(2, struct.pack('<I', 1) + eeg_hdr.encode())
    out += _chunk(2, struct.pack('<I', 2) + mk_hdr.encode())
    samples = b''.join(struct.pack('<Bd', 8, t0 + k / fs) + row.astype('<f4').tobytes()
                       for k, row in enumerate(eeg_uv))
    out += _chunk(3, struct.pack('<I', 1) + _varlen(len(eeg_uv)) + samples)
    mk = b''.join(struct.pack('<Bd', 8, t) + _varlen(len(s)) + s.encode() for t, s in markers)
    out += _chunk(3, struct.pack('<I', 2) + _varlen(len(markers)) + mk)
    for sid, first, last, n in ((1, t0, t0 + (len(eeg_uv) - 1) / fs, len(eeg_uv)),
                                (2, markers[0][0], markers[-1][0], len(markers))):
        footer = (f'<?xml version="1.0"?><info><first_timestamp>{first}</first_timestamp>'
                  f'<last_timestamp>{last}</last_timestamp><sample_count>{n}</sample_count>'
                  f'</info>')
        out += _chunk(6, struct.pack('<I', sid) + footer.encode())
    path.write_bytes(out)


def write_recording_xdf(path: Path, data: np.ndarray, fs: float, names: list[str],
                        markers: list[tuple[float, str]], t0: float = 1000.0) -> Path:
    """``data`` (n_samples, n_channels; volts) as an XDF file in microvolts, with ``markers``
    ((onset s from the first sample, text)) as string markers without duration."""
    write_xdf(path, np.asarray(data) * 1e6, fs, t0, [(t0 + o, s) for o, s in markers],
              list(names))
    return path


def write_graz_xdf(path: Path, *, trials: int = 5, fs: float = 100.0,
                   names: tuple[str, ...] = ('C3', 'Cz', 'C4'), seed: int = 0) -> Path:
    """A small Graz-like XDF session of seeded noise: per trial a ``rest`` marker, 2 s later a
    class marker (``left``, ``right``, ``hands``, ``feet`` in turn), 2 s later the next trial;
    ``trials`` trials of each class."""
    labels = ('left', 'right', 'hands', 'feet')
    n_trials = trials * len(labels)
    markers = [m for k in range(n_trials)
               for m in ((4.0 * k + 0.5, 'rest'), (4.0 * k + 2.5, labels[k % len(labels)]))]
    data = np.random.default_rng(seed).normal(0.0, 10e-6, (round((4 * n_trials + 1) * fs),
                                                            len(names)))
    return write_recording_xdf(path, data, fs, list(names), markers)
