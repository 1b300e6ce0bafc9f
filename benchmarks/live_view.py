"""Live view cost: CPU of the Foxglove bridge next to the CPU of the demo it serves.

    .venv/bin/python benchmarks/live_view.py                 # 30 s per phase
    .venv/bin/python benchmarks/live_view.py --seconds 60
    .venv/bin/python benchmarks/live_view.py --poll-period 0     # a wake per message

Runs ``mindgrasp launch demo trials:=0`` (every node its own process, no recording) with the live
view on a free port, then measures the CPU time of every process of the launch with psutil:

1. idle: no Foxglove client connected (the bridge only discovers topics);
2. layout: one WebSocket client (Foxglove protocol) subscribed to the topics of the shipped layout
   (mindgrasp_bringup/foxglove/mindgrasp_live.json), reading as fast as it can (what the Foxglove
   app does with that layout open);
3. all topics: the same client subscribed to every advertised channel (the worst case).

Prints, per phase, the bridge's CPU (% of one core), the rest of the demo's CPU (% of one core)
and the bridge's share ``bridge / rest`` (target: < 5 %), plus the messages and MB the client
received. The last line is a JSON object with every figure.
"""

from __future__ import annotations

import argparse
import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
import uuid
from pathlib import Path

import psutil
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from mindgrasp_bringup.live_layout import TOPICS


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return int(s.getsockname()[1])


def _cpu_seconds(root: psutil.Process) -> dict[int, tuple[str, float]]:
    """pid -> (label, user + system CPU s) of the launcher's descendants."""
    out = {}
    for proc in root.children(recursive=True):
        try:
            times = proc.cpu_times()
            cmd = ' '.join(proc.cmdline())
        except psutil.Error:
            continue
        label = 'bridge' if 'foxglove_bridge_node' in cmd else 'demo'
        out[proc.pid] = (label, times.user + times.system)
    return out


def _measure(root: psutil.Process, seconds: float) -> dict[str, float]:
    before = _cpu_seconds(root)
    t0 = time.monotonic()
    time.sleep(seconds)
    after = _cpu_seconds(root)
    wall = time.monotonic() - t0
    used = {'bridge': 0.0, 'demo': 0.0}
    for pid, (label, cpu) in after.items():
        used[label] += cpu - before.get(pid, (label, 0.0))[1]
    bridge, demo = 100 * used['bridge'] / wall, 100 * used['demo'] / wall
    return {'bridge_cpu_pct': bridge, 'demo_cpu_pct': demo,
            'bridge_share_pct': 100 * bridge / demo if demo else float('nan')}


class Client(threading.Thread):
    """A Foxglove WebSocket client subscribed to every channel; counts what it receives."""

    def __init__(self, port: int, topics: tuple[str, ...] | None = None) -> None:
        super().__init__(daemon=True)
        self.port = port
        self.wanted = topics  # None: every channel
        self.messages = 0
        self.bytes = 0
        self.topics: set[str] = set()
        self.stop = threading.Event()

    def run(self) -> None:
        with connect(f'ws://127.0.0.1:{self.port}', subprotocols=['foxglove.sdk.v1'],
                     proxy=None, open_timeout=30, max_size=None) as ws:
            next_id = 1
            while not self.stop.is_set():
                try:
                    frame = ws.recv(timeout=0.2)
                except TimeoutError:
                    continue
                except ConnectionClosed:  # the launch ended
                    return
                if isinstance(frame, str):
                    op = json.loads(frame)
                    if op.get('op') == 'advertise':
                        subs = []
                        for ch in op['channels']:
                            if self.wanted is not None and ch['topic'] not in self.wanted:
                                continue
                            subs.append({'id': next_id, 'channelId': ch['id']})
                            self.topics.add(ch['topic'])
                            next_id += 1
                        if subs:
                            ws.send(json.dumps({'op': 'subscribe', 'subscriptions': subs}))
                    continue
                self.messages += 1
                self.bytes += len(frame)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--seconds', type=float, default=30.0, help='measurement per phase (s)')
    parser.add_argument('--warmup', type=float, default=25.0, help='start-up before measuring')
    parser.add_argument('--poll-period', type=float, default=None,
                        help="the bridge's poll_period (s; 0: each message as it arrives); "
                             "default: the node's")
    args = parser.parse_args()
    port = _free_port()
    run_dir = Path(tempfile.mkdtemp(prefix='mg-live-view-'))
    env = dict(os.environ)
    if args.poll_period is not None:  # a parameter file for the bridge, as `mindgrasp session`
        params = run_dir.with_name(run_dir.name + '-bridge.yaml')
        params.write_text(f'/foxglove_bridge:\n  ros__parameters:\n'
                          f'    poll_period: {args.poll_period}\n', encoding='utf-8')
        env['MINDGRASP_PARAMS_FILES'] = str(params)
    stream = f'mg-live-view-bench-{uuid.uuid4().hex[:8]}'  # LSL names are host-wide
    cmd = [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'demo', 'trials:=0',
           'record:=false', f'live_view_port:={port}', f'eeg_stream:={stream}',
           f'duration:={args.warmup + 3 * args.seconds + 40}', '--run-dir', str(run_dir)]
    launcher = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                start_new_session=True, env=env)
    try:
        time.sleep(args.warmup)
        root = psutil.Process(launcher.pid)
        idle = _measure(root, args.seconds)
        phases = {'idle (no client)': idle}
        for name, topics in (('layout (1 client, its topics)', TOPICS),
                             ('all topics (1 client)', None)):
            client = Client(port, topics)
            client.start()
            time.sleep(3.0)  # subscribed to what is advertised
            count0, bytes0 = client.messages, client.bytes
            result = _measure(root, args.seconds)
            result['client_msgs_per_s'] = (client.messages - count0) / args.seconds
            result['client_mb_per_s'] = (client.bytes - bytes0) / args.seconds / 1e6
            result['topics'] = len(client.topics)
            client.stop.set()
            client.join(10)
            phases[name] = result
    finally:
        launcher.send_signal(2)
        try:
            launcher.wait(60)
        except subprocess.TimeoutExpired:
            launcher.kill()
    print(f'machine: {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}')
    for name, r in phases.items():
        line = (f'{name:30s} bridge {r["bridge_cpu_pct"]:5.1f} % of a core, rest of the demo '
                f'{r["demo_cpu_pct"]:6.1f} %, bridge/demo {r["bridge_share_pct"]:4.1f} %')
        if 'client_msgs_per_s' in r:
            line += (f'; client got {r["client_msgs_per_s"]:.0f} msg/s, '
                     f'{r["client_mb_per_s"]:.2f} MB/s on {r["topics"]} topics')
        print(line)
    print(json.dumps(phases))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
