"""What each bag tool reads of a damaged copy of a run's bag (issue 42: damage costs only the
damaged chunks).

Run: ``.venv/bin/python benchmarks/bag_damage.py runs/<time>_demo [--across-headers]
[--seed 42]`` (record one first: ``mindgrasp launch demo duration:=60``).

The run is copied to a temporary directory and 4096 random bytes (``--seed``) are written at 1/3,
1/2 and 2/3 of its ``bag_0.mcap`` (``--across-headers``: centred on the chunk header nearest to
each, which breaks the record framing itself). Printed: messages recorded and readable (``bag
info``'s check), messages the reader yields (``bag play``, ``replay``), EEG samples the export and
the classifier's loader read, predictions ``bag latency`` times, and messages ``bag reindex``
keeps, each as a share of the undamaged bag's.
"""

from __future__ import annotations

import argparse
import random
import shutil
import tempfile
from pathlib import Path

import numpy as np
from mcap.reader import make_reader

from mindgrasp_bag import BagReader
from mindgrasp_bag.damage import assess_bag
from mindgrasp_bag.integrity import reindex
from mindgrasp_bag.latency import LatencyError, latency_report
from mindgrasp_bag.paths import resolve_bag
from mindgrasp_bag.run_stamps import read_run_stamps
from mindgrasp_classifier.data import load_bag
from mindgrasp_eeg.export import read_session

DAMAGE = 4096


def damage(path: Path, seed: int, across_headers: bool) -> None:
    """Overwrite DAMAGE random bytes at 1/3, 1/2, 2/3 of ``path`` (or across chunk headers)."""
    with path.open('rb') as f:
        starts = [c.chunk_start_offset for c in make_reader(f).get_summary().chunk_indexes]
    data = bytearray(path.read_bytes())
    rng = random.Random(seed)
    for fraction in (1 / 3, 1 / 2, 2 / 3):
        at = int(len(data) * fraction)
        if across_headers:
            at = min(starts, key=lambda s: abs(s - at)) - DAMAGE // 2
        data[at:at + DAMAGE] = rng.randbytes(DAMAGE)
    path.write_bytes(bytes(data))


def measure(run: Path) -> dict[str, int]:
    """What each tool reads of ``run``."""
    bag = resolve_bag(run)
    with BagReader(bag) as reader:
        messages = sum(1 for _ in reader.messages())
    export = read_session(run)
    training = load_bag(run, labels='intent')
    try:
        timed = latency_report(read_run_stamps(bag))['end_to_end']['count']
    except LatencyError:
        timed = 0
    return {'bag info (readable)': assess_bag(bag).readable_messages,
            'reader / play / replay (messages)': messages,
            'export eeg (samples)': len(export.data) - export.n_missing,
            'train classifier (samples)': int(np.isfinite(training.data[:, 0]).sum()),
            'bag latency (predictions timed)': timed}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('run', help='run directory (runs/<run>) with an undamaged bag')
    parser.add_argument('--across-headers', action='store_true',
                        help='centre each damage on the nearest chunk header')
    parser.add_argument('--seed', type=int, default=42, help='seed of the random bytes (42)')
    args = parser.parse_args()
    clean = measure(Path(args.run))
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(shutil.copytree(args.run, Path(tmp) / 'run'))
        damage(resolve_bag(run) / 'bag_0.mcap', args.seed, args.across_headers)
        damaged = measure(run)
        kept = reindex(resolve_bag(run))[0]
    print(f'{"tool":<36}{"undamaged":>11}{"damaged":>10}{"share":>8}')
    for name, value in clean.items():
        print(f'{name:<36}{value:>11}{damaged[name]:>10}{damaged[name] / max(value, 1):>8.1%}')
    print(f'bag reindex: {kept}')


if __name__ == '__main__':
    main()
