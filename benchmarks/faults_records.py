"""What a full disk and a damaged bag cost on a real demo run (issue 31, items 1 and 2).

    python benchmarks/faults_records.py                       # 3 MB and 20 MB disks, both bags
    python benchmarks/faults_records.py --disk-mb 3 --duration 60
    python benchmarks/faults_records.py --run runs/<run>       # damage a copy of an existing run

Full disk (needs root for the tmpfs; skipped with the reason otherwise): ``mindgrasp launch demo
trials:=0`` with its run directory on a small tmpfs; prints the trial records kept (finished
trials), written to the run directory, written to the fallback folder and dropped; the
recorder's count vs what a reader recovers from the bag; truncated (0-byte) files; tracebacks;
and whether ``bag info`` on the full disk changed any file. Damaged bag: a demo run's bag cut in
half, and with three chunks damaged (a flipped bit); prints messages recorded vs readable,
records skipped, bag time lost, what ``bag play`` published, and ``replay``'s agreement and exit
code. Prints figures only; nothing is asserted. ``benchmarks/faults.py`` calls
:func:`full_disk` and :func:`damaged_bag`.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import uuid
from pathlib import Path
from typing import Any

import yaml

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / 'tests'))

from conftest_bag import cut_in_half, damage_chunks  # noqa: E402
from mindgrasp_bag import BagReader  # noqa: E402
from mindgrasp_common.safe_files import fallback_folder  # noqa: E402
from mindgrasp_experiments.records import read_records  # noqa: E402

DAMAGES = {'cut in half': cut_in_half, 'three damaged chunks': damage_chunks}


def _mindgrasp(*args: str, env: dict[str, str] | None = None,
               timeout: float = 1200) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args], capture_output=True,
                          text=True, env=env, timeout=timeout, check=False)


def _env(**extra: str) -> dict[str, str]:
    env = dict(os.environ, NO_COLOR='1', **extra)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return env


def _demo(run_dir: Path, duration: float, **env: str) -> subprocess.CompletedProcess:
    """A headless demo (every node its own process) recorded to ``run_dir``."""
    return _mindgrasp('launch', 'demo', 'trials:=0', f'duration:={duration:g}',
                      'live_view_port:=0', f'eeg_stream:=mg-faults-{uuid.uuid4().hex[:8]}',
                      '--sigint-timeout', '20', '--run-dir', str(run_dir), env=_env(**env))


def _readable(bag: Path) -> int:
    with BagReader(bag) as reader:
        return sum(1 for _ in reader.messages())


def _records(folder: Path) -> int:
    try:
        return len(read_records(folder))
    except (FileNotFoundError, OSError):
        return 0


def full_disk(size_mb: int, duration: float, workdir: Path) -> dict[str, Any]:
    """The demo on a ``size_mb`` MB tmpfs for ``duration`` s; what was kept and lost."""
    if os.geteuid() != 0:
        return {'disk_mb': size_mb, 'skipped': 'needs root to mount a tmpfs'}
    mount = workdir / f'disk_{size_mb}mb'
    mount.mkdir(parents=True)
    state = workdir / f'state_{size_mb}mb'
    done = subprocess.run(['mount', '-t', 'tmpfs', '-o', f'size={size_mb}M', 'tmpfs',
                           str(mount)], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return {'disk_mb': size_mb, 'skipped': f'mount failed: {done.stderr.strip()}'}
    try:
        run_dir = mount / 'run'
        result = _demo(run_dir, duration, XDG_STATE_HOME=str(state))
        out = result.stdout + result.stderr
        copy = fallback_folder(run_dir, state / 'mindgrasp' / 'unwritten')
        finished = len(re.findall(r'\[trial_manager\]: Trial \d+ \(.*\): ', out))
        interrupted = sum(int(n) for n in re.findall(r'(\d+) interrupted, not counted', out))
        in_run = _records(run_dir / 'trials')
        in_fallback = _records(copy / 'trials')
        kept = max(in_run, in_fallback)
        said = re.search(r'(\d+) message\(s\) are on disk and recoverable', out)
        lost = re.search(r'(\d+) lost to the write error', out)
        bag = run_dir / 'bag'
        before = {p.name: p.stat().st_size for p in bag.iterdir()} if bag.is_dir() else {}
        info = _mindgrasp('bag', 'info', str(run_dir), env=_env())
        after = {p.name: p.stat().st_size for p in bag.iterdir()} if bag.is_dir() else {}
        empty = sorted(str(p.relative_to(run_dir)) for p in run_dir.rglob('*')
                       if p.is_file() and p.stat().st_size == 0)
        return {
            'disk_mb': size_mb, 'duration_s': duration, 'exit_code': result.returncode,
            'trials_finished': finished, 'trials_interrupted': interrupted,
            'records_in_run_dir': in_run, 'records_in_fallback': in_fallback,
            'records_dropped': max(0, finished + interrupted - kept),
            'fallback': str(copy) if copy.exists() else None,
            'summary_in': ('run dir' if (run_dir / 'summary.yaml').exists() else
                           'fallback' if (copy / 'summary.yaml').exists() else 'nowhere'),
            'recorder_says_recoverable': int(said.group(1)) if said else None,
            'recorder_says_lost': int(lost.group(1)) if lost else None,
            'bag_readable': _readable(bag) if bag.is_dir() else 0,
            'empty_files': empty, 'tracebacks': out.count('Traceback'),
            'bag_info_exit_code': info.returncode, 'bag_info_wrote': before != after,
        }
    finally:
        subprocess.run(['umount', '-l', str(mount)], check=False)


def damaged_bag(run: Path | None, duration: float, workdir: Path) -> dict[str, Any]:
    """A demo run's bag cut in half and with three damaged chunks: what each tool reports."""
    if run is None:
        run = workdir / 'demo_run'
        result = _demo(run, duration)
        if not (run / 'bag').is_dir():
            return {'skipped': f'the demo recorded no bag (exit {result.returncode}): '
                               f'{result.stderr[-500:]}'}
    out: dict[str, Any] = {'run': str(run)}
    for name, damage in DAMAGES.items():
        copy = workdir / name.replace(' ', '_')
        shutil.copytree(run, copy, ignore=shutil.ignore_patterns('replays'))
        damage(copy / 'bag' / 'bag_0.mcap')
        info = _mindgrasp('bag', 'info', '--yaml', '--allow-damaged', str(copy), env=_env())
        counts = (yaml.safe_load(info.stdout) or {}).get('damage') or {}
        play = _mindgrasp('bag', 'play', str(copy), '--rate', '20', '--delay', '0',
                          '--no-progress', '--topics', '/eeg/raw', '/bci/prediction',
                          env=_env())
        played = re.search(r'Published (\d+) message', play.stdout + play.stderr)
        replay = _mindgrasp('replay', str(copy), '--json', '--no-progress', '-o',
                            str(workdir / f'{copy.name}_replay'), env=_env())
        lines = replay.stdout.strip().splitlines()
        summary = json.loads(lines[-1]) if lines and lines[-1].startswith('{') else {}
        out[name] = {
            'recorded': counts.get('expected_messages'),
            'readable': counts.get('readable_messages'),
            'lost': counts.get('lost_messages'), 'skipped_records': counts.get('skipped_records'),
            'cut_files': counts.get('cut_files'), 'lost_span_s': counts.get('lost_span_s'),
            'bag_info_exit_code': info.returncode,
            'bag_play_published': int(played.group(1)) if played else None,
            'bag_play_exit_code': play.returncode,
            'replay_exit_code': replay.returncode,
            'replay_agreement': summary.get('prediction_agreement'),
            'replay_counts_damage': bool((summary.get('damage') or {}).get('damaged')),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--disk-mb', type=int, nargs='*', default=[3, 20],
                        help='tmpfs sizes for the full-disk runs (default: 3 20)')
    parser.add_argument('--duration', type=float, default=60.0,
                        help='length of each demo run in s (default: 60)')
    parser.add_argument('--run', type=Path, default=None,
                        help='damage copies of this run instead of recording a new one')
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix='faults_records_') as tmp:
        work = Path(tmp)
        for size in args.disk_mb:
            figures = full_disk(size, args.duration, work)
            print(f'full disk, {size} MB tmpfs:')
            for key, value in figures.items():
                print(f'  {key}: {value}')
        figures = damaged_bag(args.run, args.duration, work)
        for name, value in figures.items():
            if isinstance(value, dict):
                print(f'damaged bag, {name}:')
                for key, v in value.items():
                    print(f'  {key}: {v}')
            else:
                print(f'damaged bag {name}: {value}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
