"""Every node stops within 1 s of SIGINT (and of SIGTERM), in each state it can wait in.

Each case starts the node as its own process, waits for the state (a line of its log), sends the
signal and measures the time until the process has exited. The figures are printed (``-s``) for
the reliability note. The bound is the one an operator relies on, 1 s, on a machine with a free
core; on an oversubscribed machine (load average above the core count) every process waits for a
core in proportion, so the bound scales with load / cores. A node that blocks (a resolve in
``__init__``, a slow interpreter teardown: 2-30 s) fails either way.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
import uuid

import pytest

pytestmark = pytest.mark.slow

STOP_WITHIN = 1.0   # s, from the signal to the process' exit, with a free core


def bound() -> float:
    """The stop bound (s) at the machine's current load."""
    return STOP_WITHIN * max(1.0, os.getloadavg()[0] / (os.cpu_count() or 1))

STREAM = f'mg_stop_{uuid.uuid4().hex[:8]}'   # LSL names are host-wide

# (case, module, parameters, log line that says the node is in the state)
CASES = [
    ('acquisition searching', 'mindgrasp_eeg.acquisition_node',
     {'stream_name': f'{STREAM}_absent', 'resolve_timeout': 120.0},
     'Searching for the LSL stream'),
    ('virtual_amp streaming', 'mindgrasp_eeg.virtual_amp_node', {'stream_name': f'{STREAM}_amp'},
     'Virtual amplifier'),
    ('fsm waiting for inputs', 'mindgrasp_fsm.fsm_node', {}, 'Grasp controller ready'),
    ('sim realtime', 'mindgrasp_sim.sim_node', {}, 'Simulating scene'),
    ('sim lockstep waiting for /sim/step', 'mindgrasp_sim.sim_node', {'time_mode': 'lockstep'},
     'Simulating scene'),
    ('sim fast', 'mindgrasp_sim.sim_node', {'time_mode': 'fast'}, 'Simulating scene'),
    ('vision waiting for images', 'mindgrasp_vision.vision_node', {}, 'Vision ready'),
    ('classifier waiting for EEG', 'mindgrasp_classifier.classifier_node', {}, 'Loaded'),
    ('trainer waiting for the robot', 'mindgrasp_trainer.trainer_node', {'robot_timeout': 120.0},
     'waiting for /trainer_robot/joint_states'),
    ('graz session running', 'mindgrasp_trainer.graz_node', {'n_trials': 40},
     'Graz-BCI session'),
    ('recorder recording', 'mindgrasp_bag.recorder_node', {}, 'Recording to'),
    ('player waiting for the next message', 'mindgrasp_bag.player_node', {}, 'Playing'),
]


def stop_time(proc, sig: int = signal.SIGINT) -> float:
    """Seconds from sending ``sig`` to the exit of ``proc`` (a NodeProcess)."""
    t0 = time.monotonic()
    proc.proc.send_signal(sig)
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:  # reported as the measured (too long) time
        return float('inf')
    return time.monotonic() - t0


def start(spawn_node, tmp_path, module: str, params: dict, ready: str):
    if module.endswith('recorder_node'):
        params = {'output': str(tmp_path / 'bag'), 'topics': '[/chatter]', **params}
    if module.endswith('player_node'):   # two messages 10 min apart: it waits for the second
        from conftest_bag import STRING, string
        from mindgrasp_bag import BagWriter

        with BagWriter(tmp_path / 'bag') as writer:
            writer.add_topic(f'/{STREAM}/chatter', STRING)
            for k, stamp in enumerate((1, 600 * 10**9)):
                writer.write(f'/{STREAM}/chatter', stamp, string(f'message {k}'))
        params = {'bag': str(tmp_path / 'bag'), **params}
    proc = spawn_node(module, **params)
    assert proc.wait_for_output(ready, 120.0), proc.output()
    return proc


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
@pytest.mark.parametrize(('case', 'module', 'params', 'ready'), CASES, ids=[c[0] for c in CASES])
def test_node_stops_within_a_second(spawn_node, tmp_path, case, module, params, ready, sig):
    proc = start(spawn_node, tmp_path, module, params, ready)
    took = stop_time(proc, sig)
    limit = bound()
    print(f'STOP {case} {signal.Signals(sig).name}: {took:.3f} s (bound {limit:.1f} s)')
    assert took < limit, f'{case}: {took:.2f} s\n{proc.output()[-3000:]}'
    assert proc.poll() == 0, f'{case}: exit code {proc.poll()} (a stop is 0)\n{proc.output()}'
    assert 'Traceback' not in proc.output(), proc.output()


def test_acquisition_stops_promptly_while_streaming_and_while_the_stream_is_lost(spawn_node):
    stream = f'{STREAM}_acq'
    amp = spawn_node('mindgrasp_eeg.virtual_amp_node', stream_name=stream)
    acq = spawn_node('mindgrasp_eeg.acquisition_node', stream_name=stream)
    assert acq.wait_for_output('Connected to', 120.0), acq.output()
    took = stop_time(acq)
    print(f'STOP acquisition streaming SIGINT: {took:.3f} s')
    assert took < bound(), acq.output()
    acq = spawn_node('mindgrasp_eeg.acquisition_node', stream_name=stream)
    assert acq.wait_for_output('Connected to', 120.0), acq.output()
    amp.stop()
    assert acq.wait_for_output('is lost', 120.0), acq.output()      # now reconnecting
    took = stop_time(acq)
    print(f'STOP acquisition stream lost (reconnecting) SIGINT: {took:.3f} s')
    assert took < bound(), acq.output()
