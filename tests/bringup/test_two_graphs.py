"""Two sessions never cross (issue 42): two demos at once on two ROS domains each hear only
their own amplifier (same LSL stream name, real LSL, real processes); a second graph on one
domain is refused in one line, before anything starts, and the first runs on.

Conditions are waited for with generous deadlines; nothing here measures time.
"""

from __future__ import annotations

import fcntl
import json
import os
import signal
import subprocess
import tempfile
import time
import uuid
from pathlib import Path

import pytest
import yaml
from launch_fixtures.runner import kill_group, run_launch, start_launch

pytestmark = pytest.mark.slow

#: a demo without the live view and the recorder: the processes these tests are about
LIGHT = ('live_view:=false', 'record:=false', 'trials:=0', 'duration:=600',
         '--sigint-timeout', '20')


def _second_domain() -> tuple[int, object]:
    """Another ROS domain held for this test (the same lock files as tests/conftest.py)."""
    for i in range(231):
        domain = 1 + (os.getpid() * 7 + 101 + i) % 231
        if str(domain) == os.environ.get('ROS_DOMAIN_ID'):
            continue
        lock = (Path(tempfile.gettempdir()) / f'mindgrasp-test-domain-{domain}.lock').open('w')
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        return domain, lock
    raise RuntimeError('no free ROS domain id on this host')


def _wait_for(condition, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.5)
    return condition()


def _log(run_dir: Path, label: str) -> str:
    path = run_dir / 'logs' / f'{label}.log'
    return path.read_text(errors='replace') if path.is_file() else ''


def _amp_source_id(run_dir: Path) -> str:
    params = yaml.safe_load((run_dir / 'params' / 'virtual_amp.yaml').read_text())
    return params['/**']['ros__parameters']['source_id']


def _stop(proc: subprocess.Popen) -> tuple[int, str]:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=180)
    finally:
        kill_group(proc)
    return proc.returncode, err


@pytest.mark.timeout(1500)
def test_two_demos_on_two_domains_each_hear_their_own_amplifier(tmp_path: Path) -> None:
    """The issue's scenario: demo B starts while demo A streams, with the same LSL stream name;
    B's acquisition used to connect to A's amplifier before its own existed."""
    stream = f'mg-two-{uuid.uuid4().hex[:8]}'            # the same name for both demos
    domain_b, lock = _second_domain()
    runs = {'a': tmp_path / 'a', 'b': tmp_path / 'b'}
    procs = {}
    try:
        procs['a'] = start_launch('demo', *LIGHT, f'eeg_stream:={stream}', 'seed:=1',
                                  '--run-dir', str(runs['a']))
        metadata = {k: run / 'eeg_stream.json' for k, run in runs.items()}
        assert _wait_for(metadata['a'].is_file, 400), _log(runs['a'], 'eeg_acquisition')
        procs['b'] = start_launch('demo', *LIGHT, f'eeg_stream:={stream}', 'seed:=2',
                                  '--run-dir', str(runs['b']), ROS_DOMAIN_ID=str(domain_b))
        assert _wait_for(metadata['b'].is_file, 400), _log(runs['b'], 'eeg_acquisition')
        own = {k: _amp_source_id(run) for k, run in runs.items()}
        assert own['a'] != own['b'], own
        for key, run in runs.items():
            heard = json.loads(metadata[key].read_text())
            assert heard['name'] == stream and heard['source_id'] == own[key], (key, heard)
            log = _log(run, 'eeg_acquisition')
            assert f"source_id '{own[key]}'" in log and 'is not pinned' not in log, log[-2000:]
            assert f"source_id '{own['b' if key == 'a' else 'a']}'" not in log, log[-2000:]
        # both keep streaming their own EEG: B's start cost A nothing (no loss, no refusal)
        assert 'is lost' not in _log(runs['a'], 'eeg_acquisition')
        assert all(p.poll() is None for p in procs.values())
    finally:
        results = {k: _stop(p) for k, p in procs.items()}
        lock.close()
    for key, (code, err) in results.items():
        assert code == 130, (key, err[-3000:])           # interrupted by SIGINT, cleanly


@pytest.mark.timeout(900)
def test_a_second_demo_on_the_same_domain_is_refused_in_one_line(tmp_path: Path) -> None:
    first_dir, second_dir = tmp_path / 'first', tmp_path / 'second'
    stream = f'mg-one-{uuid.uuid4().hex[:8]}'
    first = start_launch('demo', *LIGHT, f'eeg_stream:={stream}', '--run-dir', str(first_dir))
    try:
        assert _wait_for(lambda: 'Grasp controller ready' in _log(first_dir, 'fsm')
                         and 'Simulating scene' in _log(first_dir, 'sim'), 400), \
            _log(first_dir, 'fsm')
        # generous discovery period: the machine may be loaded
        second = run_launch('demo', *LIGHT, f'eeg_stream:={stream}-2', '--graph-check', '10',
                            '--run-dir', str(second_dir), timeout=300)
        lines = [line for line in second.stderr.splitlines() if line.strip()]
        assert second.returncode == 2, second.stderr[-3000:]
        assert len(lines) == 1 and 'Traceback' not in second.stderr, second.stderr[-3000:]
        domain = os.environ['ROS_DOMAIN_ID']
        assert f'another graph runs on ROS_DOMAIN_ID={domain}' in lines[0], lines[0]
        assert 'ROS_DOMAIN_ID=' in lines[0].split('Launch on another domain')[1], lines[0]
        assert not second_dir.exists()                    # nothing was created, nothing started
        assert first.poll() is None                       # the first demo runs on
    finally:
        code, err = _stop(first)
    assert code == 130, err[-3000:]
    summary = yaml.safe_load((first_dir / 'summary.yaml').read_text())
    assert all(p['clean'] for p in summary['processes']), summary


@pytest.mark.parametrize(('module', 'ready', 'params'), [
    ('mindgrasp_fsm.fsm_node', 'Grasp controller ready', {}),
    ('mindgrasp_sim.sim_node', 'Simulating scene', {'camera_rate': 1.0}),
])
def test_a_second_node_of_one_graph_refuses_to_start(spawn_node, module, ready, params):
    """What ``ros2 launch`` or ``mindgrasp run`` starts: the node itself looks for its twin (by
    name through the graph API, and a second publisher of its output) and refuses in one line."""
    first = spawn_node(module, **params)
    assert first.wait_for_output(ready, timeout=120), first.output()
    second = spawn_node(module, graph_check_wait=10.0, **params)
    code = second.wait(timeout=120)
    lines = [line for line in second.output().splitlines() if 'ERROR' in line]
    assert code == 2, second.output()
    assert len(lines) == 1 and 'Traceback' not in second.output(), second.output()
    domain = os.environ['ROS_DOMAIN_ID']
    assert f'Another ROS graph runs on ROS_DOMAIN_ID={domain}' in lines[0], lines[0]
    assert first.poll() is None, first.output()            # the first one runs on

