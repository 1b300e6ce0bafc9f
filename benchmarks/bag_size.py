"""Bag size and the recorder's CPU cost, with and without compression and the default exclusions.

Run: ``.venv/bin/python benchmarks/bag_size.py [RUN_OR_BAG] [--duration 60] [--profile demo]
[NAME:=VALUE ...]`` (e.g. ``--profile graz --duration 22 display:=headless``)

Without a bag it records one first (``mindgrasp launch <profile> duration:=<duration>
record_compression:=none record_exclude_regex:=`` into a temporary run directory, so every topic
is kept). The bag's messages are then read into memory once and written again by the project's
:class:`~mindgrasp_bringup.bag.BagWriter` (what the recorder node runs) with each compression,
with every topic and without the topics the default ``record_exclude_regex`` leaves out. Printed
per setting: bag size (MiB and MiB per recorded minute) and the writer's CPU time per recorded
minute (``time.process_time`` around the writes only, so reading the source bag is not counted),
then the largest topics.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

from mindgrasp_bringup.bag import BagReader, BagWriter
from mindgrasp_bringup.launch_system.run_extras import DEFAULT_RECORD_EXCLUDE

COMPRESSIONS = ('none', 'lz4', 'zstd')


def record(profile: str, duration: float, runs: Path, arguments: list[str]) -> Path:
    """Record ``profile`` for ``duration`` s with every topic and no compression; its bag."""
    run_dir = runs / f'bag_size_{profile}'
    cmd = [sys.executable, '-m', 'mindgrasp_bringup', 'launch', profile, f'duration:={duration}',
           'record_compression:=none', 'record_exclude_regex:=', *arguments,
           '--run-dir', str(run_dir)]
    print(f'recording: {" ".join(cmd[2:])}', flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return run_dir / 'bag'


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
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='bag_size_') as tmp:
        tmp_path = Path(tmp)
        if args.bag and ':=' in args.bag:
            args.arguments.insert(0, args.bag)
            args.bag = None
        bag = (Path(args.bag) if args.bag
               else record(args.profile, args.duration, tmp_path, args.arguments))
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
