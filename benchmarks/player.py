"""Bag player timing over real DDS: how far publications stray from the bag's schedule.

Run: ``ROS_DOMAIN_ID=16 .venv/bin/python benchmarks/player.py [--seconds 5] [--runs 3]``

Writes a bag (EEG chunks at 25 Hz and strings at 100 Hz), plays it with the player node as its own
process into a probe process, and compares the DDS source timestamps (taken by the player when it
publishes) with the bag's timestamps, relative to their median offset. Two ways of running the
same ``PlayerNode`` are compared:

* ``poll``: the node as shipped (``run_node(..., poll_sec=0.05)``: the main thread runs ready
  callbacks without waiting in the middleware and sleeps on ``done`` in between);
* ``blocking``: ``run_node`` without ``poll_sec`` (the main thread waits in the DDS WaitSet).

Prints per mode and run: messages, median / 90th percentile / max error (ms).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'tests'))

from conftest_bag import EEG, PROBE, STRING, eeg_chunk, string  # noqa: E402
from mindgrasp_bag import BagReader, BagWriter  # noqa: E402

T0 = 1_750_000_000_000_000_000
MS = 1_000_000

BLOCKING = '''
import sys
sys.setswitchinterval(0.0005)   # as player_node.main
from mindgrasp_bag.errors import BagError
from mindgrasp_bag.player_node import PlayerNode
from mindgrasp_ros.node_main import run_node
sys.exit(run_node(PlayerNode, sys.argv, errors=(BagError,)))
'''


def write_bag(path: Path, prefix: str, seconds: float) -> None:
    with BagWriter(path) as writer:
        writer.add_topic(f'{prefix}/eeg', EEG)
        writer.add_topic(f'{prefix}/text', STRING)
        messages = [(T0 + k * 40 * MS, f'{prefix}/eeg', eeg_chunk(25 * k))
                    for k in range(int(seconds * 25))]
        messages += [(T0 + 3 * MS + k * 10 * MS, f'{prefix}/text', string(f'm{k}'))
                     for k in range(int(seconds * 100))]
        for stamp, topic, data in sorted(messages):
            writer.write(topic, stamp, data)


class Probe:
    """The subscriber process; collects ``topic stamp sha1`` lines."""

    def __init__(self, topics: list[str]) -> None:
        env = {**os.environ, 'PYTHONUNBUFFERED': '1'}
        self.proc = subprocess.Popen([sys.executable, '-c', PROBE, *topics], env=env,
                                     stdout=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        for line in self.proc.stdout:  # type: ignore[union-attr]
            self.lines.append(line.rstrip('\n'))

    def wait_ready(self, timeout: float = 60.0) -> None:
        deadline = time.monotonic() + timeout
        while 'ready' not in self.lines:
            if time.monotonic() > deadline or self.proc.poll() is not None:
                raise RuntimeError('the probe did not start')
            time.sleep(0.05)

    def stop(self) -> None:
        self.proc.terminate()
        self.proc.wait(10)


def play(mode: str, bag: Path, prefix: str) -> tuple[int, float, float, float]:
    probe = Probe([f'{prefix}/eeg={EEG}', f'{prefix}/text={STRING}'])
    try:
        probe.wait_ready()
        args = ['--ros-args', '-p', f'bag:={bag}', '-p', 'delay:=1.0']
        cmd = ([sys.executable, '-m', 'mindgrasp_bag.player_node', *args]
               if mode == 'poll' else [sys.executable, '-c', BLOCKING, *args])
        subprocess.run(cmd, check=True, capture_output=True, timeout=300)
        time.sleep(0.5)
    finally:
        probe.stop()
    sent = {}
    for line in probe.lines:
        if line.startswith('/'):
            topic, stamp, _digest = line.split()
            sent.setdefault(topic, []).append(int(stamp))
    errors = []
    with BagReader(bag) as reader:
        for topic in (f'{prefix}/eeg', f'{prefix}/text'):
            stamps = np.array([s for t, s, _ in reader.messages() if t == topic], dtype=np.int64)
            got = np.array(sent.get(topic, []), dtype=np.int64)
            if len(got) != len(stamps):
                raise RuntimeError(f'{topic}: {len(got)} of {len(stamps)} messages arrived')
            offset = got - stamps
            errors.append(np.abs(offset - np.median(offset)) / 1e6)
    e = np.concatenate(errors)
    return len(e), float(np.median(e)), float(np.percentile(e, 90)), float(e.max())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=5.0, help='length of the bag (s)')
    parser.add_argument('--runs', type=int, default=3, help='runs per mode')
    args = parser.parse_args()
    prefix = f'/bench_play_{uuid.uuid4().hex[:8]}'
    print(f'load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores')
    print(f'{"mode":10} {"messages":>8} {"median ms":>10} {"p90 ms":>8} {"max ms":>8}')
    with tempfile.TemporaryDirectory() as tmp:
        bag = Path(tmp) / 'bag'
        write_bag(bag, prefix, args.seconds)
        for _ in range(args.runs):
            for mode in ('poll', 'blocking'):   # alternated: the same load for both
                n, median, p90, worst = play(mode, bag, prefix)
                print(f'{mode:10} {n:>8} {median:>10.2f} {p90:>8.2f} {worst:>8.2f}', flush=True)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
