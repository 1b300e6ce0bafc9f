"""Run directories: every launch gets its own, even two in the same second."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import pytest

from mindgrasp_bringup.launch_system import LaunchError, rundir


def test_launches_in_the_same_second_get_their_own_directories(tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(rundir, 'utc_stamp', lambda now=None: '20261122T000000Z')
    with ThreadPoolExecutor(8) as pool:
        paths = list(pool.map(lambda _: rundir.create_run_dir('demo', None, tmp_path), range(8)))
    assert len(set(paths)) == 8
    assert sorted(p.name for p in paths) == sorted(
        ['20261122T000000Z_demo'] + [f'20261122T000000Z_demo-{n}' for n in range(2, 9)])
    assert all((p / 'logs').is_dir() for p in paths)


def test_an_explicit_run_dir_with_files_is_refused(tmp_path) -> None:
    (tmp_path / 'bag').mkdir()
    with pytest.raises(LaunchError, match='exists and is not empty'):
        rundir.create_run_dir('demo', tmp_path)
    empty = tmp_path / 'empty'
    empty.mkdir()
    assert rundir.create_run_dir('demo', empty) == empty.resolve()
