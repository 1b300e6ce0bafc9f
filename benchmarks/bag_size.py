"""Bag size and the recorder's CPU cost, with and without compression and the default exclusions.

Run: ``.venv/bin/python benchmarks/bag_size.py [RUN_OR_BAG] [--duration 60] [--profile demo]
[--live] [NAME:=VALUE ...]`` (e.g. ``--profile graz --duration 22 display:=headless``)

Without a bag it records one first (``mindgrasp launch <profile> duration:=<duration>
record_compression:=none record_exclude_regex:=`` into a temporary run directory, so every topic
is kept). The bag's messages are then read into memory once and written again by the project's
:class:`~mindgrasp_bag.BagWriter` (what the recorder node runs) with each compression,
with every topic and without the topics the default ``record_exclude_regex`` leaves out. Printed
per setting: bag size (MiB and MiB per recorded minute) and the writer's CPU time per recorded
minute (``time.process_time`` around the writes only, so reading the source bag is not counted),
then the largest topics. ``--live`` instead launches the profile twice, recording everything
uncompressed and then with the defaults, and prints each bag's size and the recorder process's CPU
time per recorded minute.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import psutil

from mindgrasp_bag import BagReader, BagWriter
from mindgrasp_launch.run_extras import DEFAULT_RECORD_EXCLUDE

COMPRESSIONS = ('none', 'lz4', 'zstd')


#: launch arguments of a recording that keeps every topic uncompressed
EVERYTHING = ('record_compression:=none', 'record_exclude_regex:=')


def record(profile: str, duration: float, run_dir: Path, arguments: list[str]
           ) -> tuple[Path, float]:
    """Launch ``profile`` for ``duration`` s; its bag and the recorder process's CPU seconds
    (sampled every 0.2 s until it ends, so the last ~0.2 s of closing may be missed)."""
    cmd = [sys.executable, '-m', 'mindgrasp_cli', 'launch', profile, f'duration:={duration}',
           *arguments, '--run-dir', str(run_dir)]
    print(f'recording: {" ".join(cmd[2:])}', flush=True)
    launch = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    cpu: dict[int, float] = {}
    while launch.poll() is None:
        for child in psutil.Process(launch.pid).children(recursive=True):
            with contextlib.suppress(psutil.Error):
                if any('recorder_node' in part for part in child.cmdline()):
                    times = child.cpu_times()
                    cpu[child.pid] = times.user + times.system
        time.sleep(0.2)
    if launch.returncode != 0:
        msg = f'the launch failed (exit code {launch.returncode}); see {run_dir}/logs'
        raise SystemExit(msg)
    return run_dir / 'bag', sum(cpu.values())


def live(profile: str, duration: float, tmp: Path, arguments: list[str]) -> None:
    """The same launch recorded both ways: everything uncompressed, and the defaults."""
    print(f'{"recording":<22} {"MiB":>8} {"MiB/min":>8} {"recorder CPU s/min":>19}')
    for label, extra in (('everything, none', EVERYTHING), ('defaults', ())):
        bag, cpu = record(profile, duration, tmp / label.replace(' ', '_').replace(',', ''),
                          [*arguments, *extra])
        size = sum(f.stat().st_size for f in bag.rglob('*') if f.is_file())
        with BagReader(bag) as reader:
            minutes = max(reader.open().duration_ns / 60e9, 1e-9)
        print(f'{label:<22} {size / 2**20:8.1f} {size / 2**20 / minutes:8.1f} '
              f'{cpu / minutes:19.2f}', flush=True)


def load(bag: Path) -> tuple[BagReader, list[tuple[str, int, bytes]]]:
    """The bag's reader (topics, duration) and all its messages in memory."""
    reader = BagReader(bag).open()
    messages = list(reader.messages())
    return reader, messages


def rewrite(reader: BagReader, messages: list[tuple[str, int, bytes]], out: Path,
            compression: str, exclude: str) -> tuple[int, float]:
    """Write ``messages`` to a new bag; (bytes on disk, writer CPU seconds)."""
    skip = re.compile(exclude) if exclude else None
    keep = [t for t in reader.topics if skip is None or not skip.search(t)]
    start = time.process_time()
    with BagWriter(out, compression=compression) as writer:
        for topic in keep:
            info = reader.topics[topic]
            writer.add_topic(topic, info.type, offered_qos_profiles=info.offered_qos_profiles)
        wanted = set(keep)
        for topic, stamp, data in messages:
            if topic in wanted:
                writer.write(topic, stamp, data)
    cpu = time.process_time() - start
    size = sum(f.stat().st_size for f in out.rglob('*') if f.is_file())
    return size, cpu


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('bag', nargs='?', help='a run directory or bag (default: record one)')
    parser.add_argument('arguments', nargs='*', metavar='NAME:=VALUE',
                        help='launch arguments of the recording')
    parser.add_argument('--profile', default='demo', help='launch profile to record (demo)')
    parser.add_argument('--duration', type=float, default=60.0, help='seconds to record (60)')
    parser.add_argument('--live', action='store_true',
                        help='launch the profile twice (everything uncompressed; the defaults) '
                             "and compare the bags and the recorder's CPU time")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='bag_size_') as tmp:
        tmp_path = Path(tmp)
        if args.bag and ':=' in args.bag:
            args.arguments.insert(0, args.bag)
            args.bag = None
        if args.live:
            live(args.profile, args.duration, tmp_path, args.arguments)
            return 0
        bag = (Path(args.bag) if args.bag
               else record(args.profile, args.duration, tmp_path / 'run',
                           [*args.arguments, *EVERYTHING])[0])
        if (bag / 'bag').is_dir():
            bag = bag / 'bag'
        reader, messages = load(bag)
        minutes = max(reader.duration_ns / 60e9, 1e-9)
        print(f'source: {bag} ({reader.message_count} messages, {minutes * 60:.1f} s)')
        print(f'default record_exclude_regex: {DEFAULT_RECORD_EXCLUDE!r}')
        print(f'{"compression":<12} {"topics":<10} {"MiB":>8} {"MiB/min":>8} '
              f'{"CPU s/min":>10}')
        for exclude, label in (('', 'all'), (DEFAULT_RECORD_EXCLUDE, 'default')):
            for compression in COMPRESSIONS:
                out = tmp_path / f'out_{label}_{compression}'
                size, cpu = rewrite(reader, messages, out, compression, exclude)
                shutil.rmtree(out)
                print(f'{compression:<12} {label:<10} {size / 2**20:8.1f} '
                      f'{size / 2**20 / minutes:8.1f} {cpu / minutes:10.2f}', flush=True)
        per_topic: dict[str, int] = defaultdict(int)
        for topic, _, data in messages:
            per_topic[topic] += len(data)
        print('largest topics (uncompressed MiB/min):')
        for topic, size in sorted(per_topic.items(), key=lambda kv: -kv[1])[:6]:
            print(f'  {topic:<32} {size / 2**20 / minutes:8.1f}')
        reader.close()
    return 0


if __name__ == '__main__':
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    sys.exit(main())
