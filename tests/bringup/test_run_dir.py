"""Run directories: every launch gets its own, even two in the same second."""

from __future__ import annotations

import re
from concurrent.futures import ThreadPoolExecutor

import pytest
import yaml

from mindgrasp_launch import LaunchError, rundir
from mindgrasp_launch.run_extras import (
    DEFAULT_RECORD_EXCLUDE,
    RunFiles,
    duration_limit,
    record_enabled,
    recorder_parameters,
)


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


def test_run_files_of_another_launcher_are_complete_whenever_it_stops(tmp_path) -> None:
    """What ros2 launch's RunDirectory action writes (mindgrasp_launch.launch_ros_extras)."""
    path = rundir.create_run_dir('demo', None, tmp_path)
    files = RunFiles(path)
    files.write_start(profile='demo', launch_file='/ws/share/demo.launch.py',
                      launcher='ros2 launch', command_line=['ros2', 'launch', 'x'],
                      arguments={'trials': '1', 'record': 'true'}, record=True, duration=None,
                      logs='/home/u/.ros/log/x')
    launch = yaml.safe_load((path / 'launch.yaml').read_text())
    assert (launch['profile'], launch['launcher'], launch['record']) == ('demo', 'ros2 launch',
                                                                        True)
    assert yaml.safe_load((path / 'launch_arguments.yaml').read_text()) == {
        'record': 'true', 'trials': '1'}
    assert 'git' in yaml.safe_load((path / 'provenance.yaml').read_text())
    assert not (path / 'summary.yaml').exists()
    files.process_ended('trial_manager_node-2', 41, 0)
    summary = yaml.safe_load((path / 'summary.yaml').read_text())
    assert summary['processes'] == [
        {'label': 'trial_manager_node-2', 'pid': 41, 'returncode': 0, 'clean': True}]
    files.stopping("process[trial_manager_node-2] was required")
    files.process_ended('recorder_node-1', 40, -2)
    summary = yaml.safe_load((path / 'summary.yaml').read_text())
    assert summary['stop_reason'] == 'process[trial_manager_node-2] was required'
    assert [(p['label'], p['clean']) for p in summary['processes']] == [
        ('trial_manager_node-2', True), ('recorder_node-1', False)]


@pytest.mark.parametrize(('arguments', 'record', 'duration', 'parameters'), [
    ({}, True, None, {'output': 'R/bag', 'parameter_changes': 'R/params/changes.jsonl',
                      'exclude_regex': DEFAULT_RECORD_EXCLUDE, 'compression': 'zstd'}),
    ({'record': 'false', 'duration': '30', 'record_topics': '/a, /b /c', 'record_regex': '/x.*',
      'record_exclude_regex': '', 'record_compression': 'none'},
     False, 30.0, {'output': 'R/bag', 'parameter_changes': 'R/params/changes.jsonl',
                   'topics': ['/a', '/b', '/c'], 'regex': '/x.*',
                   'exclude_regex': '', 'compression': 'none'}),
])
def test_both_launchers_read_the_common_arguments_alike(arguments, record, duration,
                                                         parameters) -> None:
    assert record_enabled(arguments) is record
    assert duration_limit(arguments) == duration
    assert recorder_parameters(arguments, 'R/bag') == parameters


@pytest.mark.parametrize(('name', 'value', 'problem'), [
    ('record', 'maybe', "'record' expects true or false, got 'maybe'"),
    ('duration', '-1', "'duration' must be a number of seconds >= 0"),
    ('duration', 'nan', "'duration' must be a number of seconds >= 0"),
])
def test_a_bad_common_argument_is_one_clear_error(name, value, problem) -> None:
    with pytest.raises(LaunchError, match=re.escape(problem)):
        record_enabled({name: value}) if name == 'record' else duration_limit({name: value})


def test_summary_on_a_full_disk_keeps_the_old_file_and_goes_to_the_fallback(
        tmp_path, monkeypatch, caplog) -> None:
    """ENOSPC at the file layer: the summary is never truncated, and it is not lost."""
    import errno
    from pathlib import Path

    from mindgrasp_common.safe_files import fallback_folder

    monkeypatch.setenv('XDG_STATE_HOME', str(tmp_path / 'state'))
    path = rundir.create_run_dir('demo', None, tmp_path / 'runs')
    files = RunFiles(path)
    files.process_ended('sim-1', 40, 0)
    real_write_text = Path.write_text

    def full_disk(self: Path, text: str, *args, **kwargs) -> int:
        if path in self.parents:          # the run directory's disk is full
            real_write_text(self, text[:10], *args, **kwargs)
            raise OSError(errno.ENOSPC, 'No space left on device')
        return real_write_text(self, text, *args, **kwargs)

    monkeypatch.setattr(Path, 'write_text', full_disk)
    files.process_ended('fsm-2', 41, 0)
    files.stopping('the duration ended')          # still full: no second line
    monkeypatch.undo()
    old = yaml.safe_load((path / 'summary.yaml').read_text())
    assert [p['label'] for p in old['processes']] == ['sim-1']       # intact, not truncated
    copy = fallback_folder(path, tmp_path / 'state' / 'mindgrasp' / 'unwritten')
    new = yaml.safe_load((copy / 'summary.yaml').read_text())
    assert [p['label'] for p in new['processes']] == ['sim-1', 'fsm-2']
    assert new['stop_reason'] == 'the duration ended'
    errors = [r.getMessage() for r in caplog.records if r.name == 'launch']
    assert len(errors) == 1 and str(copy) in errors[0] and 'No space left' in errors[0]


def test_a_launch_on_a_full_disk_is_refused_in_one_line_before_anything_starts(tmp_path):
    import contextlib

    from launch_fixtures.runner import run_launch

    from mindgrasp_testing import small_tmpfs

    with small_tmpfs(tmp_path / 'full', '256k') as disk:
        with (disk / 'filler').open('wb', buffering=0) as f, \
                contextlib.suppress(OSError):      # until the disk is full
            while True:
                f.write(b'\0' * 4096)
        result = run_launch('demo', 'duration:=5', '--run-dir', str(disk / 'run'), timeout=120)
    assert result.returncode == 2, result.stderr
    assert 'Traceback' not in result.stderr
    errors = [line for line in result.stderr.splitlines() if 'error' in line.lower()]
    assert len(errors) == 1 and 'cannot write the run directory' in errors[0], result.stderr
    assert 'No space left on device' in errors[0] and '--run-dir' in errors[0]
    assert 'process started' not in result.stderr
