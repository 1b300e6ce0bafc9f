"""The launcher with real processes (plain Python fixture scripts): output, logs, exit codes,
crash reports, respawn, signals, duration and the run directory."""

from __future__ import annotations

import io
import os
import re
import signal
import time
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import (
    BRINGUP_TESTS,
    fixture,
    kill_group,
    run_launch,
    start_launch,
    wait_for_file_text,
)

from mindgrasp_launch import (
    LaunchDescription,
    LaunchService,
    Node,
    Shutdown,
)
from mindgrasp_launch.output import Printer
from mindgrasp_launch.run_extras import DEFAULT_RECORD_EXCLUDE

pytestmark = pytest.mark.slow


def read_yaml(path: Path) -> dict:
    return yaml.safe_load(path.read_text(encoding='utf-8'))


def test_two_processes_end_cleanly_and_fill_the_run_directory(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    result = run_launch(fixture('two_tickers.launch.py'), 'record:=false', 'rate:=2.5',
                        '--run-dir', str(run_dir))
    assert result.returncode == 0, result.stderr
    assert '[first] first tick 2' in result.stdout and '[second] second tick 2' in result.stdout
    assert 'every process ended cleanly' in result.stderr
    # per-node logs hold the same lines, without prefix
    first_log = (run_dir / 'logs' / 'first.log').read_text()
    assert 'first tick 0\nfirst tick 1\nfirst tick 2\n' in first_log
    assert f'env MINDGRASP_RUN_DIR={run_dir.resolve()}' in first_log
    assert 'process started with pid' in (run_dir / 'logs' / 'launch.log').read_text()
    # the node got its resolved parameters with --params-file, as ros2 launch passes them
    assert read_yaml(run_dir / 'params' / 'first.yaml') == {
        '/**': {'ros__parameters': {'rate': 2.5, 'tag': 'one'}}}
    assert '"__ns:=/grp", "--params-file"' in first_log
    assert read_yaml(run_dir / 'params.yaml')['/grp/first'] == {
        'ros__parameters': {'rate': 2.5, 'tag': 'one'}}
    arguments = read_yaml(run_dir / 'launch_arguments.yaml')
    assert arguments == {'count': '3', 'exit_code': '0', 'rate': '2.5', 'record': 'false',
                         'record_topics': '', 'record_regex': '',
                         'record_exclude_regex': DEFAULT_RECORD_EXCLUDE,
                         'record_compression': 'zstd', 'duration': '0'}
    provenance = read_yaml(run_dir / 'provenance.yaml')
    assert re.fullmatch(r'[0-9a-f]{40}', provenance['git']['revision'])
    assert provenance['packages']['mindgrasp-ros'] and provenance['packages']['numpy']
    assert provenance['ros_environment']['ROS_DOMAIN_ID']
    launch = read_yaml(run_dir / 'launch.yaml')
    assert launch['profile'] == 'two_tickers'
    assert launch['processes'][0]['node'] == '/grp/first'
    assert '--params-file' in launch['processes'][0]['command']
    summary = read_yaml(run_dir / 'summary.yaml')
    assert summary['exit_code'] == 0 and summary['stop_reason'] == 'every node has ended'
    assert [p['how'] for p in summary['processes']] == ['finished', 'finished']


def test_default_run_directory_is_timestamped_under_runs(tmp_path: Path) -> None:
    result = run_launch(fixture('two_tickers.launch.py'), 'record:=false', 'count:=1',
                        MINDGRASP_RUNS_DIR=str(tmp_path))
    assert result.returncode == 0, result.stderr
    (run_dir,) = tmp_path.iterdir()
    assert re.fullmatch(r'\d{8}T\d{6}Z_two_tickers', run_dir.name)
    assert (run_dir / 'summary.yaml').is_file()


def test_a_dying_node_is_reported_and_stops_the_launch(tmp_path: Path) -> None:
    result = run_launch(fixture('crash.launch.py'), 'record:=false', '--run-dir',
                        str(tmp_path / 'run'))
    assert result.returncode == 1
    err = result.stderr
    assert re.search(r"process 'crasher' \(pid \d+\) died: exit code 5\. last \d+ lines of "
                     r"\S+crasher\.log:", err), err
    assert '    | crasher tick 2\n    | crasher done, exit code 5' in err
    assert "stopping the launch: process 'crasher' died (exit code 5)" in err
    assert 'the launch ended with failures: crasher (died, 5)' in err
    assert '[survivor] stopping on SIGINT' in result.stdout
    summary = read_yaml(tmp_path / 'run' / 'summary.yaml')
    assert summary['exit_code'] == 1
    assert {p['label']: p['clean'] for p in summary['processes']} == {'survivor': True,
                                                                     'crasher': False}


def test_an_arm_driver_that_exits_0_at_once_stops_the_hardware_launch(tmp_path: Path) -> None:
    """Issue 31, item 9: a driver that ended with exit code 0 left the launch running without
    an arm and ending with exit 0. A driver is a required node: its end stops every process,
    says so in one line, and the launch fails."""
    result = run_launch('hardware', 'eeg_stream:=nobody', 'eeg_unpinned:=true', 'arm_driver:=true',
                        'record:=false',
                        'model:=package://mindgrasp_classifier/models/default_classifier.json',
                        '--run-dir', str(tmp_path / 'run'), timeout=120.0)
    assert result.returncode == 1, result.stderr
    err = result.stderr
    assert re.search(r"required process 'arm_driver' \(pid \d+\) ended \(exit code 0\) while "
                     r'the launch was running; stopping every process\.', err), err
    assert "stopping the launch: required process 'arm_driver' ended" in err
    summary = read_yaml(tmp_path / 'run' / 'summary.yaml')
    assert summary['exit_code'] == 1
    ended = {p['label']: p for p in summary['processes']}
    assert not ended['arm_driver']['clean']
    assert all(p['returncode'] is not None for p in summary['processes'])   # none left running


def test_respawn_restarts_a_dead_node(tmp_path: Path) -> None:
    marker = tmp_path / 'crashed-once'
    result = run_launch(fixture('respawn.launch.py'), 'record:=false', f'marker:={marker}',
                        '--run-dir', str(tmp_path / 'run'))
    # respawned, but the run is not clean: a node died during it (last line, exit code, summary)
    assert result.returncode == 1, result.stderr
    assert re.search(r"the launch ended with failures: phoenix \(finished, 0; died and was "
                     r"respawned 1 time\(s\)\)", result.stderr.strip().splitlines()[-1])
    assert re.search(r"process 'phoenix' \(pid \d+\) died: exit code 3; respawning in 0\.2 s "
                     r"\(respawn=True, restart 1\)", result.stderr)
    assert '    | crashing once on purpose' in result.stderr
    log = (tmp_path / 'run' / 'logs' / 'phoenix.log').read_text()
    assert '--- launch: restarting' in log and 'phoenix done, exit code 0' in log
    summary = read_yaml(tmp_path / 'run' / 'summary.yaml')
    assert summary['processes'][0]['restarts'] == 1 and not summary['processes'][0]['clean']
    assert summary['exit_code'] == 1 and summary['clean'] is False
    # without respawn the same death ends the launch with a failure
    marker.unlink()
    result = run_launch(fixture('respawn.launch.py'), 'record:=false', f'marker:={marker}',
                        'respawn:=false', '--run-dir', str(tmp_path / 'run2'))
    assert result.returncode == 1
    assert "process 'phoenix'" in result.stderr and 'died: exit code 3' in result.stderr


def _started(run_dir: Path, *labels: str) -> None:
    for label in labels:
        assert wait_for_file_text(run_dir / 'logs' / f'{label}.log', f'{label} tick 1'), label


@pytest.mark.parametrize('signum', [signal.SIGTERM, signal.SIGINT])
def test_signal_stops_nodes_in_reverse_order_cleanly(tmp_path: Path, signum: int) -> None:
    run_dir = tmp_path / 'run'
    proc = start_launch(fixture('forever.launch.py'), 'record:=false', '--run-dir', str(run_dir))
    try:
        _started(run_dir, 'alpha', 'beta')
        proc.send_signal(signum)
        out, err = proc.communicate(timeout=30)
    finally:
        kill_group(proc)
    # interrupted, as a shell reports it: 128 + the signal (130 Ctrl-C, 143 SIGTERM), and said
    assert proc.returncode == 128 + signum, err
    assert f'stopping the launch: {signal.Signals(signum).name} received' in err
    assert f'the launch was interrupted ({signal.Signals(signum).name}) before its end' in err
    assert 'every process ended cleanly' not in err
    assert read_yaml(run_dir / 'summary.yaml')['interrupted_by'] == signal.Signals(signum).name
    order = re.findall(r'process has finished cleanly \[pid \d+\]: (\w+)', err)
    assert order == ['beta', 'alpha']  # started alpha, beta: stopped beta first
    assert '[alpha] stopping on SIGINT' in out and '[beta] stopping on SIGINT' in out


def test_a_node_ignoring_sigint_gets_sigterm_and_fails_the_launch(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    proc = start_launch(fixture('forever.launch.py'), 'record:=false', 'stubborn:=true',
                        '--sigint-timeout', '0.5', '--run-dir', str(run_dir))
    try:
        _started(run_dir, 'alpha', 'stubborn')
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        kill_group(proc)
    assert proc.returncode == 1
    assert re.search(r"process 'stubborn' \(pid \d+\) did not stop 0\.5 s after SIGINT; "
                     r"sending SIGTERM", err)
    assert 'the launch ended with failures: stubborn (stopped by SIGTERM, -15)' in err


def test_duration_ends_the_launch(tmp_path: Path) -> None:
    start = time.monotonic()
    result = run_launch(fixture('forever.launch.py'), 'record:=false', '--duration', '1.5',
                        '--run-dir', str(tmp_path / 'run'))
    assert result.returncode == 0, result.stderr
    assert time.monotonic() - start >= 1.5
    summary = read_yaml(tmp_path / 'run' / 'summary.yaml')
    assert summary['stop_reason'] == 'duration of 1.5 s reached'
    assert read_yaml(tmp_path / 'run' / 'launch_arguments.yaml')['duration'] == '1.5'


def _pids(launch_log: Path) -> list[int]:
    return [int(p) for p in re.findall(r'pid \[(\d+)\]', launch_log.read_text())]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_children_do_not_outlive_a_killed_launcher(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    proc = start_launch(fixture('forever.launch.py'), 'record:=false', '--run-dir', str(run_dir))
    try:
        _started(run_dir, 'alpha', 'beta')
        pids = _pids(run_dir / 'logs' / 'launch.log')
        assert len(pids) == 2
        proc.kill()  # SIGKILL: no chance to stop the nodes itself
        proc.wait(timeout=10)
        deadline = time.monotonic() + 10
        while any(_alive(p) for p in pids) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(_alive(p) for p in pids)
    finally:
        kill_group(proc)


def test_in_process_service_on_exit_shutdown_and_log_only_output(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv('PYTHONPATH', str(BRINGUP_TESTS))
    out, err = io.StringIO(), io.StringIO()
    description = LaunchDescription([
        Node(package='launch_fixtures', executable='ticker', name='endless',
             arguments=['--count', '0']),
        Node(package='launch_fixtures', executable='ticker', name='quiet', output='log',
             arguments=['--count', '2', '--label', 'quiet'], on_exit=Shutdown()),
    ])
    service = LaunchService(description, ['record:=false'], run_dir=tmp_path / 'run',
                            printer=Printer(out, err))
    assert service.run() == 0
    assert service.stop_reason == "'quiet' ended and has on_exit=Shutdown()"
    assert '[endless] stopping on SIGINT' in out.getvalue()
    assert '[quiet]' not in out.getvalue() + err.getvalue()
    assert 'quiet tick 1' in (tmp_path / 'run' / 'logs' / 'quiet.log').read_text()


def test_output_prefix_is_coloured_on_a_terminal() -> None:
    class Tty(io.StringIO):
        def isatty(self) -> bool:
            return True

    tty, plain = Tty(), io.StringIO()
    coloured = Printer(tty, tty)
    coloured.colour = True  # as use_colour() decides for a TTY without NO_COLOR
    coloured.line('sim', 'hello')
    coloured.line('fsm', 'hi')
    Printer(plain, plain).line('sim', 'hello')
    assert tty.getvalue().startswith('\x1b[32m[sim]\x1b[0m hello\n')
    assert '\x1b[36m[fsm]\x1b[0m hi' in tty.getvalue()
    assert plain.getvalue() == '[sim] hello\n'


def test_existing_run_directory_is_never_overwritten(tmp_path: Path) -> None:
    (tmp_path / 'run').mkdir()
    (tmp_path / 'run' / 'keep.txt').write_text('data')
    result = run_launch(fixture('two_tickers.launch.py'), 'record:=false', '--run-dir',
                        str(tmp_path / 'run'))
    assert result.returncode == 2
    assert 'exists and is not empty: choose a new --run-dir' in result.stderr
    assert (tmp_path / 'run' / 'keep.txt').read_text() == 'data'


def test_missing_profile_module_fails_before_starting_anything(tmp_path: Path) -> None:
    launch_file = tmp_path / 'missing.launch.py'
    launch_file.write_text(
        'from mindgrasp_launch import LaunchDescription, Node\n'
        'def generate_launch_description():\n'
        '    return LaunchDescription([Node(package="launch_fixtures", executable="ticker"),\n'
        '        Node(package="mindgrasp_sim", executable="not_written_yet", name="sim")])\n')
    result = run_launch(str(launch_file), 'record:=false', MINDGRASP_RUNS_DIR=str(tmp_path / 'r'))
    assert result.returncode == 2
    assert "sim: the node module 'mindgrasp_sim.not_written_yet' does not exist" in result.stderr
    assert not (tmp_path / 'r').exists()  # nothing started, no run directory


def test_nodes_get_sigint_even_when_the_launcher_started_with_it_ignored(tmp_path: Path) -> None:
    # `mindgrasp launch demo &` in a script starts the launcher with SIGINT ignored; the nodes
    # must still stop on SIGINT (Python only raises KeyboardInterrupt if SIGINT is not ignored)
    import subprocess

    from launch_fixtures.runner import launch_cmd, launch_env

    run_dir = tmp_path / 'run'
    proc = subprocess.Popen(
        launch_cmd(fixture('interrupt.launch.py'), 'record:=false', '--run-dir', str(run_dir)),
        env=launch_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    try:
        _started(run_dir, 'gamma')
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=30)
    finally:
        kill_group(proc)
    assert proc.returncode == 130, err          # interrupted by SIGINT, cleanly
    assert '[gamma] stopping on KeyboardInterrupt' in out


def test_a_launch_with_nothing_to_start_ends_at_once(tmp_path: Path) -> None:
    from mindgrasp_launch import IfCondition

    description = LaunchDescription([Node(package='launch_fixtures', executable='ticker',
                                          condition=IfCondition('false'))])
    service = LaunchService(description, ['record:=false'], run_dir=tmp_path / 'run',
                            printer=Printer(io.StringIO(), io.StringIO()))
    assert service.run() == 0
    assert service.stop_reason == 'the launch description starts no process'
