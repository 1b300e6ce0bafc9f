"""The timing report: per hop and end to end latency of the BCI loop from a run's bag, in the
run's report.md and from ``mindgrasp bag latency RUN [--json]``.

Unit tests drive :func:`latency_report` with stamps whose answer is known; the multi-process
tests run the live loop (virtual amplifier, acquisition, classifier, controller and recorder as
separate processes over DDS and LSL) and read its real MCAP bag.
"""

from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

import numpy as np
import psutil
import pytest
from launch_fixtures.runner import fixture, kill_group, launch_env, run_launch, start_launch

from conftest_bag import EEG, JOINTS, eeg_chunk, joints
from mindgrasp_bag import BagError, BagReader, BagWriter
from mindgrasp_bag.latency import LatencyError, RunStamps, latency_report
from mindgrasp_bag.run_stamps import read_run_stamps
from mindgrasp_launch.run_report import write_run_report

MS = 1_000_000
T0 = 1_795_000_000_000_000_000   # a wall-clock time (ns)


def _loop(n_chunks: int = 40, e2e_extra_ms: int = 0) -> RunStamps:
    """Chunks of 8 samples at 250 Hz (32 ms) published 5 ms after their last sample; one
    prediction per chunk ending on its 4th sample, published 2 ms after the chunk; commands every
    20 ms from T0 + 3 ms."""
    first = T0 + np.arange(n_chunks, dtype=np.int64) * 32 * MS
    last = first + 28 * MS
    chunk_pub = last + 5 * MS
    pred_stamp = first + 12 * MS
    pred_pub = chunk_pub + 2 * MS + e2e_extra_ms * MS
    commands = T0 + 3 * MS + np.arange(n_chunks * 2 + 4, dtype=np.int64) * 20 * MS
    return RunStamps(chunk_first_ns=first, chunk_last_ns=last, chunk_pub_ns=chunk_pub,
                     pred_stamp_ns=pred_stamp, pred_pub_ns=pred_pub, command_pub_ns=commands,
                     periodic_ns={'/eeg/raw': chunk_pub, '/arm_controller/commands': commands},
                     nominal_period_s={'/eeg/raw': 0.032})


def test_hops_add_up_to_the_end_to_end_latency_of_each_prediction() -> None:
    report = latency_report(_loop())
    hops = report['hops']
    assert list(hops) == ['acquisition', 'classifier', 'controller']
    assert hops['acquisition']['p50_ms'] == pytest.approx(21.0)   # 16 ms to chunk end + 5 ms
    assert hops['acquisition']['p99_ms'] == pytest.approx(21.0)
    assert hops['classifier']['p50_ms'] == pytest.approx(2.0)
    # predictions at T0 + 35 + 32 k ms; commands at T0 + 3 + 20 j ms: the wait for the next tick
    k = np.arange(40)
    wait = (3 + 20 * np.ceil((35 + 32 * k - 3) / 20) - (35 + 32 * k))
    assert hops['controller']['p50_ms'] == pytest.approx(np.percentile(wait, 50))
    assert hops['controller']['p99_ms'] == pytest.approx(np.percentile(wait, 99))
    e2e = report['end_to_end']
    assert e2e['count'] == 40 and e2e['p95_ms'] == pytest.approx(np.percentile(23 + wait, 95))
    assert all(h['count'] == 40 for h in hops.values())
    jitter = report['jitter']
    assert jitter['/eeg/raw']['nominal_from'] == 'parameter'
    assert jitter['/eeg/raw']['p99_ms'] == pytest.approx(0.0)
    assert jitter['/arm_controller/commands']['nominal_hz'] == pytest.approx(50.0)
    assert jitter['/arm_controller/commands']['nominal_from'] == 'median interval'
    assert report['cue_to_flip'] is None


def test_cue_to_flip_pairs_each_prompt_with_its_flip() -> None:
    stamps = _loop()
    stamps.cue_ns = {(1, 'cue'): T0, (1, 'rest'): T0 + 4000 * MS, (2, 'cue'): T0 + 8000 * MS}
    stamps.flip_ns = {(1, 'cue'): T0 + 16 * MS, (1, 'rest'): T0 + 4017 * MS}
    report = latency_report(stamps)
    assert report['cue_to_flip']['count'] == 2
    assert report['cue_to_flip']['p50_ms'] == pytest.approx(16.5)


def test_predictions_without_their_chunk_are_left_out_with_a_note() -> None:
    stamps = _loop()
    stamps.pred_stamp_ns = stamps.pred_stamp_ns - 10_000 * MS * (np.arange(40) < 3)
    report = latency_report(stamps)
    assert report['end_to_end']['count'] == 37
    assert report['notes'] == [
        '3 of 40 predictions were left out: the /eeg/raw chunk of their last sample or a later '
        'command is not in the bag (recorded before the recorder started or after it stopped, '
        'or in a damaged chunk).']


@pytest.mark.parametrize(('change', 'match'), [
    ({'chunk_first_ns': np.zeros(0, np.int64), 'chunk_last_ns': np.zeros(0, np.int64),
      'chunk_pub_ns': np.zeros(0, np.int64)}, r'^The run has no /eeg/raw messages, so there is '
                                              r'no EEG sample to time; record a live run'),
    ({'pred_stamp_ns': np.zeros(0, np.int64), 'pred_pub_ns': np.zeros(0, np.int64)},
     r'^The run has no /bci/prediction messages to pair with its EEG'),
    ({'command_pub_ns': np.zeros(0, np.int64)},
     r'^The run has no /arm_controller/commands messages'),
    ({'chunk_first_ns': np.arange(40, dtype=np.int64) * 32 * MS,
      'chunk_last_ns': np.arange(40, dtype=np.int64) * 32 * MS + 28 * MS},
     r"^The run's /eeg/raw stamps are not on the wall clock \(a lock-step run on simulated "),
    # a lock-step bag: every stamp on simulated time, from 0
    ({name: getattr(_loop(), name) - T0 for name in ('chunk_first_ns', 'chunk_last_ns',
                                                     'chunk_pub_ns', 'pred_stamp_ns',
                                                     'pred_pub_ns', 'command_pub_ns')},
     r"^The run's /eeg/raw stamps are not on the wall clock \(a lock-step run on simulated "),
    ({'pred_stamp_ns': np.full(40, T0 - 3600 * 10**9, np.int64)},
     r"^None of the run's 40 predictions pairs with a recorded /eeg/raw chunk"),
])
def test_a_run_that_cannot_give_latencies_says_why(change: dict, match: str) -> None:
    stamps = _loop()
    for name, value in change.items():
        setattr(stamps, name, value)
    with pytest.raises(LatencyError, match=match):
        latency_report(stamps)


# --- multi-process: the live loop and its bag --------------------------------------------------


def _latency_cli(run: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'latency',
                           str(run), *args], capture_output=True, text=True, timeout=120,
                          env=launch_env(), check=False)


@pytest.fixture(scope='module')
def loop_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A recorded live run of the BCI loop that ends after 30 predictions."""
    run_dir = tmp_path_factory.mktemp('latency') / 'run'
    stream = f'mg-latency-{uuid.uuid4().hex[:8]}'   # LSL names are host-wide
    # the launch ends by itself after 30 predictions; the timeout is only a safety net for a
    # loaded host (start-up of five processes and the classifier's first window)
    result = run_launch(fixture('bci_loop.launch.py'), f'eeg_stream:={stream}',
                        'predictions:=30', '--sigint-timeout', '20', '--run-dir', str(run_dir),
                        timeout=600)
    assert result.returncode == 0, result.stderr[-4000:]
    return run_dir


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_the_report_of_a_live_run_gives_each_hop_and_end_to_end(loop_run: Path) -> None:
    report = (loop_run / 'report.md').read_text(encoding='utf-8')
    assert '## Timing' in report
    # the hop table: five cells a row (the jitter table has seven)
    rows = {cells[1].strip(): cells[2:6] for cells in (line.split('|') for line in
            report.splitlines()) if len(cells) == 7 and cells[1].strip() not in ('hop', '---')}
    for hop in ('EEG sample -> /eeg/raw', '/eeg/raw -> /bci/prediction',
                '/bci/prediction -> /arm_controller/commands',
                'end to end (EEG sample -> command)'):
        p50, p95, p99, count = (float(v) for v in rows[hop])
        assert count >= 20 and 0 <= p50 <= p95 <= p99, (hop, report)
    saved = json.loads((loop_run / 'latency.json').read_text(encoding='utf-8'))
    assert saved['end_to_end']['count'] >= 20
    assert set(saved['jitter']) >= {'/eeg/raw', '/arm_controller/commands', '/bci/prediction'}
    # nominal rates come from the run's parameters where a node sets them
    assert saved['jitter']['/arm_controller/commands']['nominal_from'] == 'parameter'
    assert saved['jitter']['/eeg/raw']['nominal_hz'] == pytest.approx(32.0)


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_bag_latency_json_prints_one_object_on_the_last_line(loop_run: Path) -> None:
    result = _latency_cli(loop_run, '--json')
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert set(report['hops']) == {'acquisition', 'classifier', 'controller'}
    for stats in [report['end_to_end'], *report['hops'].values()]:
        assert {'p50_ms', 'p95_ms', 'p99_ms', 'count'} <= set(stats)
        assert stats['count'] >= 20 and stats['p50_ms'] <= stats['p99_ms']
    # end to end covers the hops (per prediction it is their sum)
    assert report['end_to_end']['p50_ms'] >= report['hops']['controller']['p50_ms']
    text = _latency_cli(loop_run / 'bag')
    assert text.returncode == 0 and 'end to end (EEG sample -> command)' in text.stdout


def _bag_run(run_dir: Path, messages: list[tuple[str, str, bytes]]) -> Path:
    """A run directory whose bag (written by our BagWriter, real MCAP) holds ``messages``."""
    with BagWriter(run_dir / 'bag') as writer:
        for topic, msgtype, _ in messages:
            writer.add_topic(topic, msgtype)
        for i, (topic, _, data) in enumerate(messages):
            writer.write(topic, T0 + i * 10 * MS, data, T0 + i * 10 * MS)
    return run_dir


@pytest.mark.parametrize(('messages', 'line'), [
    ([('/joint_states', JOINTS, joints(i)) for i in range(5)],
     'The run has no /eeg/raw messages, so there is no EEG sample to time; record a live run '
     'with EEG (e.g. `mindgrasp launch demo`).'),
    # a lock-step run: header stamps on simulated time (from 0 s), DDS stamps on the wall clock
    ([('/eeg/raw', EEG, eeg_chunk(25 * i, stamp_ns=i * 10**8)) for i in range(5)],
     "The run's /eeg/raw stamps are not on the wall clock (a lock-step run on simulated time); "
     'latencies need a live run (`mindgrasp launch demo`).'),
])
def test_a_run_without_latencies_says_why_in_one_line_and_in_its_report(
        tmp_path: Path, messages: list, line: str) -> None:
    run_dir = _bag_run(tmp_path / 'run', messages)
    cli = _latency_cli(run_dir)
    assert cli.returncode == 1 and cli.stdout == ''
    assert cli.stderr.splitlines() == [f'mindgrasp bag latency: {line}']
    write_run_report(run_dir, 'test')
    assert f'No latency figures: {line}' in (run_dir / 'report.md').read_text(encoding='utf-8')
    assert not (run_dir / 'latency.json').exists()


def test_a_run_without_a_bag_says_so_in_its_report(tmp_path: Path) -> None:
    write_run_report(tmp_path, 'test')
    assert 'No latency figures: The run has no bag (record:=false, or the recorder ended ' \
        'before it opened one)' in (tmp_path / 'report.md').read_text(encoding='utf-8')


@pytest.mark.slow
def test_a_lock_step_run_has_a_report_that_says_why_it_has_no_latencies(tmp_path: Path) -> None:
    run_dir = tmp_path / 'run'
    res = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'launch', 'graz',
                          'trials:=1', '--lockstep', '--run-dir', str(run_dir)],
                         capture_output=True, text=True, timeout=300, env=launch_env(),
                         check=False)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "No latency figures: The run's /eeg/raw stamps are not on the wall clock (a " \
        'lock-step run on simulated time)' in (run_dir / 'report.md').read_text(encoding='utf-8')


def _predictions_in(bag: Path) -> int:
    """/bci/prediction messages readable in a bag being recorded (0 before it has any)."""
    try:
        with BagReader(bag) as reader:
            return sum(1 for _ in reader.messages(['/bci/prediction']))
    except (BagError, OSError, ValueError):
        return 0


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_a_run_whose_recorder_was_killed_still_gets_its_latencies(tmp_path: Path) -> None:
    """Item 4 of issue 42: the recorder of a live run (real processes over DDS and LSL) is
    killed with SIGKILL mid-run; its bag has no footer, no summary, no metadata.yaml. The run's
    report.md and ``bag latency`` still give the figures of what reached the file, say that the
    file was not closed, and ``bag latency`` exits 1 unless --allow-damaged."""
    run_dir = tmp_path / 'run'
    stream = f'mg-latency-{uuid.uuid4().hex[:8]}'
    launch = start_launch(fixture('bci_loop.launch.py'), f'eeg_stream:={stream}',
                          '--sigint-timeout', '20', '--run-dir', str(run_dir))
    try:
        deadline = time.monotonic() + 400
        while _predictions_in(run_dir / 'bag') < 30 and time.monotonic() < deadline:
            assert launch.poll() is None, launch.communicate()[1][-3000:]
            time.sleep(2)
        assert _predictions_in(run_dir / 'bag') >= 30, 'no predictions recorded in time'
        recorders = [p for p in psutil.Process(launch.pid).children(recursive=True)
                     if any('recorder_node' in part for part in p.cmdline())]
        assert len(recorders) == 1, recorders
        recorders[0].send_signal(signal.SIGKILL)
        recorders[0].wait(30)
        time.sleep(2)
        os.kill(launch.pid, signal.SIGINT)             # the user's Ctrl-C ends the run
        _, err = launch.communicate(timeout=180)
    finally:
        kill_group(launch)
    bag = run_dir / 'bag'
    assert not (bag / 'metadata.yaml').exists()         # the recorder never closed the bag
    report = (run_dir / 'report.md').read_text(encoding='utf-8')
    assert '| end to end (EEG sample -> command) |' in report, report + err[-3000:]
    assert 'were not closed (the recorder was killed' in report, report
    saved = json.loads((run_dir / 'latency.json').read_text(encoding='utf-8'))
    assert saved['end_to_end']['count'] >= 20
    # bag latency: the same figures; the damage said, exit 1 unless --allow-damaged
    text = _latency_cli(run_dir)
    assert text.returncode == 1, text.stderr
    assert 'end to end (EEG sample -> command)' in text.stdout
    assert 'without a footer (the recorder was killed)' in text.stderr
    assert '--allow-damaged' in text.stderr.splitlines()[-1]
    allowed = _latency_cli(run_dir, '--json', '--allow-damaged')
    assert allowed.returncode == 0, allowed.stderr
    figures = json.loads(allowed.stdout.strip().splitlines()[-1])
    assert figures['end_to_end']['count'] == saved['end_to_end']['count']
    assert figures['damage']['cut_files'] == 1
    # the same bag cut at a random offset (a copy interrupted): what is before the cut is timed
    cut = tmp_path / 'cut'
    cut.mkdir()
    data = (bag / 'bag_0.mcap').read_bytes()
    at = random.Random(0).randrange(len(data) // 2, len(data))
    (cut / 'bag_0.mcap').write_bytes(data[:at])
    stamps = read_run_stamps(cut)
    assert stamps.chunk_pub_ns.size > 0 and stamps.pred_pub_ns.size > 0
    assert latency_report(stamps)['end_to_end']['count'] > 0
