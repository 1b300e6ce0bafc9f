"""Live parameter changes on record: a `param set` during a recorded run (real processes, DDS,
LSL, MCAP) is in <run>/params/changes.jsonl with its old value, in the bag's /parameter_events at
the same time, and `mindgrasp replay` applies it to the re-run controller at that time."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest
from launch_fixtures.runner import fixture, kill_group, launch_env, start_launch

from mindgrasp_bag import BagReader
from mindgrasp_bag.mcap_scan import read_mcap_contents
from mindgrasp_bag.param_changes import ParameterChangeLog, read_changes
from mindgrasp_bag.typestore import typestore

pytestmark = pytest.mark.slow


def mindgrasp(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args], env=launch_env(),
                          capture_output=True, text=True, timeout=timeout, check=False)


def wait_for(predicate, timeout: float = 120.0, period: float = 1.0) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return False


def predictions(bag: Path) -> int:
    mcap = bag / 'bag_0.mcap'
    if not mcap.exists():
        return 0
    contents = read_mcap_contents(mcap)
    return sum(n for cid, n in contents.channel_counts.items()
               if contents.channels[cid].topic == '/bci/prediction')


def test_a_live_change_is_in_the_run_dir_the_bag_and_the_replay(tmp_path):
    run = tmp_path / 'run'
    stream = f'eeg_stream:=mg-live-{uuid.uuid4().hex[:8]}'   # LSL names are host-wide
    proc = start_launch(fixture('bci_loop.launch.py'), stream, 'duration:=400',
                        '--sigint-timeout', '20', '--run-dir', str(run))
    try:
        def before() -> str | None:
            got = mindgrasp('param', 'get', '/fsm', 'lock_duration', '--hide-type')
            return got.stdout.strip() if got.returncode == 0 else None
        assert wait_for(lambda: before() is not None), 'the controller never answered'
        old = float(before())
        assert wait_for(lambda: predictions(run / 'bag') >= 5, 180)   # the loop runs
        changed = mindgrasp('param', 'set', '/fsm', 'lock_duration', str(old + 1.5))
        assert changed.returncode == 0, changed.stderr
        changes = run / 'params' / 'changes.jsonl'
        assert wait_for(lambda: changes.exists() and read_changes(changes), 60)
        n = predictions(run / 'bag')
        assert wait_for(lambda: predictions(run / 'bag') >= n + 20, 180)  # inputs after it
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        try:
            proc.wait(180)
        finally:
            kill_group(proc)

    [row] = read_changes(changes)
    assert (row['node'], row['name'], row['old'], row['new']) == \
        ('/fsm', 'lock_duration', old, old + 1.5)

    reader = BagReader(run / 'bag').open()
    try:
        events = [(t, typestore().deserialize_cdr(data, 'rcl_interfaces/msg/ParameterEvent'))
                  for _topic, t, data in reader.messages(['/parameter_events'])]
        assert '/rosout' in reader.topics
    finally:
        reader.close()
    recorded = [(t, e.node, p.name, p.value.double_value) for t, e in events
                for p in e.changed_parameters]
    assert recorded == [(row['time_ns'], '/fsm', 'lock_duration', old + 1.5)]

    done = mindgrasp('replay', str(run), '--controller', '--json', '--no-progress')
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    summary = json.loads(done.stdout.strip().splitlines()[-1])
    [applied] = summary['parameter_changes']
    assert applied['applied_ns'] == applied['time_ns'] == row['time_ns']
    assert (applied['node'], applied['name'], applied['value']) == \
        ('/fsm', 'lock_duration', old + 1.5)
    assert applied['successful'], applied


def test_change_log_keeps_old_values_and_survives_a_cut(tmp_path):
    path = tmp_path / 'params' / 'changes.jsonl'
    log = ParameterChangeLog(path)
    log.seed('/fsm', {'gain': 1.0, 'mode': 'a'})
    assert log.event(10, 9, '/fsm', {}, {'gain': 2.0}, []) == [
        {'time_ns': 10, 'node': '/fsm', 'name': 'gain', 'old': 1.0, 'new': 2.0, 'stamp_ns': 9}]
    log.seed('/fsm', {'gain': 1.0})            # an older read does not undo the change
    log.event(20, 19, '/fsm', {'extra': 3}, {'gain': 4.0, 'extra': 5}, ['mode'])
    log.event(30, 29, '/other', {}, {'x': True}, [])
    log.close()
    assert log.event(40, 39, '/fsm', {}, {'gain': 0.0}, []) == []   # after close: nothing
    path.write_text(path.read_text() + '{"time_ns": 5')             # killed mid-line
    rows = [(r['node'], r['name'], r['old'], r['new']) for r in read_changes(path)]
    assert rows == [('/fsm', 'gain', 1.0, 2.0), ('/fsm', 'gain', 2.0, 4.0),
                    ('/fsm', 'extra', 3, 5), ('/fsm', 'mode', 'a', None),
                    ('/other', 'x', None, True)]
