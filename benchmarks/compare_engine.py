"""CPU of the lock-step experiment engine against another checkout, on the same host at the same
time: two processes side by side, one core each, each running the same set-location trials with
its own code. Prints CPU s per simulated s of both, their ratio, and whether the trial records are
identical.

    python benchmarks/compare_engine.py ../old-checkout            # 3 rounds of 3 trials
    python benchmarks/compare_engine.py ../old-checkout --rounds 5 --trials 2

The host's speed varies (by up to ~40 % on a shared virtual machine); running both at once makes
the ratio the figure to trust, not the absolute CPU times. The other checkout needs
``mindgrasp_experiments.engine`` (the lock-step engine, 2026-11-23 or later).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]


def measure(trials: int, seed: int) -> dict[str, object]:
    """Trials 2..trials+1 of a virtual-subject set-location run in this process (trial 1 warms
    up: imports, first graph); CPU s per simulated s and a digest of the records."""
    from mindgrasp_experiments.engine import lockstep_components, run_trial

    comps = lockstep_components('experiment', {'protocol': 'set_locations',
                                               'subject': 'virtual', 'accuracy': '0.8',
                                               'seed': str(seed)},
                                Path(tempfile.mkdtemp()) / 'params', log=lambda _text: None)
    run_trial(comps, 1, seed=seed, log_level='error')
    cpu0, sim, records = time.process_time(), 0.0, []
    for trial in range(2, trials + 2):
        run = run_trial(comps, trial, seed=seed, log_level='error')
        sim += run.sim_s
        records.append(run.record)
    cpu = time.process_time() - cpu0
    return {'cpu_s_per_sim_s': cpu / sim, 'sim_s': sim,
            'records': hashlib.sha256(str(records).encode()).hexdigest()[:16]}


def _source_path(checkout: Path) -> str:
    src = checkout / 'src'
    if not src.is_dir():
        sys.exit(f'{checkout} is not a MIndGrasp-ROS checkout (no src/); give its top folder.')
    return os.pathsep.join(str(p) for p in sorted(src.iterdir()) if p.is_dir())


def _start(checkout: Path, trials: int, seed: int) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=_source_path(checkout))
    return subprocess.Popen([sys.executable, __file__, '--inner', str(trials), str(seed)],
                            cwd=tempfile.gettempdir(), env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True)


def _result(proc: subprocess.Popen, label: str) -> dict[str, object]:
    out, _ = proc.communicate()
    lines = out.strip().splitlines()
    if proc.returncode != 0 or not lines:
        sys.exit(f'The {label} checkout failed to run its trials (exit {proc.returncode}).')
    return json.loads(lines[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('other', type=Path, nargs='?',
                        help='top folder of the checkout to compare with')
    parser.add_argument('--rounds', type=int, default=3)
    parser.add_argument('--trials', type=int, default=3)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--inner', nargs=2, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.inner:
        print(json.dumps(measure(*args.inner)), flush=True)
        return 0
    if args.other is None:
        parser.error('give the checkout to compare with')
    ratios = []
    print(f'this checkout: {HERE}\nother: {args.other.resolve()}')
    for rnd in range(1, args.rounds + 1):
        this = _start(HERE, args.trials, args.seed)
        other = _start(args.other.resolve(), args.trials, args.seed)
        a, b = _result(this, 'this'), _result(other, 'other')
        ratio = a['cpu_s_per_sim_s'] / b['cpu_s_per_sim_s']
        ratios.append(ratio)
        same = 'identical' if a['records'] == b['records'] else 'DIFFERENT'
        print(f'round {rnd}: CPU s per simulated s: this {a["cpu_s_per_sim_s"]:.4f}, other '
              f'{b["cpu_s_per_sim_s"]:.4f}, ratio {ratio:.3f}; records {same}', flush=True)
    print(f'ratio this/other: {min(ratios):.3f}-{max(ratios):.3f} '
          f'(median {sorted(ratios)[len(ratios) // 2]:.3f})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
