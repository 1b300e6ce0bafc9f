"""Wall time and accuracy of ``mindgrasp session calibrate``: its phases in lock-step (the
default), and with ``--realtime`` the same plan in real time (``--display headless``: a screen is
drawn, so the phases keep the wall clock) for comparison.

    python benchmarks/calibrate.py                              # 10 trials per class, 0.9
    python benchmarks/calibrate.py --trials-per-class 5 --repeat 2
    python benchmarks/calibrate.py --realtime                   # + the real-time run (~6 min)

Each run is the CLI in a child process with a fresh subject folder in a temporary directory; the
figures are its ``--json`` line (``wall_time_s`` from the CLI's start to the result). The machine's
load counts: lock-step wall time is CPU-bound, real time is not.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path


def calibrate(root: Path, trials_per_class: int, accuracy: float, *,
              realtime: bool) -> dict:
    """One ``mindgrasp session calibrate --json`` run in ``root``; its JSON result."""
    cmd = [sys.executable, '-m', 'mindgrasp_cli', 'session', 'calibrate', '--subject', 'B01',
           '--root', str(root), '--virtual-accuracy', str(accuracy),
           '--trials-per-class', str(trials_per_class), '--json']
    if realtime:
        cmd += ['--display', 'headless']
    res = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if res.returncode != 0:
        print(res.stdout[-2000:] + res.stderr[-2000:], file=sys.stderr)
        msg = f'mindgrasp session calibrate failed with exit code {res.returncode}.'
        raise SystemExit(msg)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trials-per-class', type=int, default=10)
    parser.add_argument('--virtual-accuracy', type=float, default=0.9)
    parser.add_argument('--repeat', type=int, default=1, help='lock-step runs (default 1)')
    parser.add_argument('--realtime', action='store_true',
                        help='also run the plan in real time (--display headless)')
    args = parser.parse_args(argv)
    modes = ['lock-step'] * args.repeat + (['real time'] if args.realtime else [])
    print(f'session calibrate, {args.trials_per_class} trials per class, virtual accuracy '
          f'{args.virtual_accuracy}:')
    print(f"{'mode':<10} {'wall (s)':>9} {'cv acc.':>8} {'held-out':>9} {'trials':>7}")
    for mode in modes:
        with tempfile.TemporaryDirectory() as tmp:
            r = calibrate(Path(tmp), args.trials_per_class, args.virtual_accuracy,
                          realtime=mode == 'real time')
        print(f"{mode:<10} {r['wall_time_s']:>9.1f} {100 * r['cv_accuracy']:>7.1f}% "
              f"{100 * r['heldout_accuracy']:>8.1f}% {r['heldout_trials']:>7d}", flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
