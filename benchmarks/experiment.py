"""Speed of the lock-step experiment engine: real-time factor, CPU s per simulated s, and where the
time goes per node (wall s in each node's callbacks) and per function (``--profile``).

    python benchmarks/experiment.py                         # 2 set-location trials, virtual 0.8
    python benchmarks/experiment.py --subject oracle --trials 3
    python benchmarks/experiment.py --protocol random_locations --subject autonomous
    python benchmarks/experiment.py --profile 25            # + the 25 costliest functions
    python benchmarks/experiment.py --sweep --trials 8      # trials/min: 1, 2 workers, Ray
    python benchmarks/experiment.py --robot xarm6 --subject oracle --trials 3   # another arm

The trials run in this process, one after the other (``--workers`` of the CLI multiplies the
real-time factor by up to the number of free cores). The machine's load counts: the CPU figure
is the one to compare between runs.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import tempfile
import time
from pathlib import Path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--protocol', default='set_locations',
                        choices=['set_locations', 'random_locations'])
    parser.add_argument('--subject', default='virtual',
                        choices=['noise', 'virtual', 'oracle', 'autonomous'])
    parser.add_argument('--accuracy', type=float, default=0.8)
    parser.add_argument('--trials', type=int, default=2)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--step', type=float, default=0.02)
    parser.add_argument('--robot', default='mindgrasp_arm', metavar='NAME|YAML',
                        help='the arm (robot:= of the experiment profile): mindgrasp_arm, xarm6 '
                             'or a robot description YAML path')
    parser.add_argument('--profile', type=int, default=0, metavar='N',
                        help='profile with cProfile and print the N costliest functions')
    parser.add_argument('--sweep', action='store_true',
                        help='trials per minute with 1 and 2 worker processes and with Ray '
                             '(--ray auto; needs the cluster extra), and the ratio to 1 worker')
    args = parser.parse_args(argv)

    from mindgrasp_experiments.engine import lockstep_components, run_trial
    from mindgrasp_experiments.subject_launch import noise_model_path

    launch_args = {'protocol': args.protocol, 'subject': args.subject,
                   'accuracy': str(args.accuracy), 'seed': str(args.seed),
                   'robot': args.robot}
    if args.subject == 'noise':
        launch_args['model'] = noise_model_path(Path(tempfile.mkdtemp()))
    comps = lockstep_components('experiment', launch_args, Path(tempfile.mkdtemp()) / 'params',
                                log=lambda _text: None)
    if args.sweep:
        return sweep_speed(comps, args)
    prof = cProfile.Profile() if args.profile else None
    runs = []
    wall0 = time.perf_counter()
    for trial in range(1, args.trials + 1):
        if prof is not None:
            prof.enable()
        run = run_trial(comps, trial, seed=args.seed, step_s=args.step, log_level='warn')
        if prof is not None:
            prof.disable()
        runs.append(run)
        r = run.record
        print(f'trial {trial}: {r.desired:16s} success {r.success!s:5} correct '
              f'{r.correct_and_successful!s:5} {run.sim_s:6.1f} sim s in {run.wall_s:6.1f} wall s '
              f'(graph built in {run.build_s:.2f} s), {r.failure or "ok"}', flush=True)
    wall = time.perf_counter() - wall0
    sim = sum(r.sim_s for r in runs)
    cpu = sum(r.cpu_s for r in runs)
    print(f'\n{args.protocol}, subject {args.subject}, robot {args.robot}: {len(runs)} trials, '
          f'{sim:.0f} simulated s in {wall:.0f} s wall: real-time factor {sim / wall:.1f}; '
          f'{cpu / sim:.3f} CPU s per simulated s (= {sim / cpu:.1f}x real time per free core)')
    node_s: dict[str, float] = {}
    for r in runs:
        for name, sec in r.node_s.items():
            node_s[name] = node_s.get(name, 0.0) + sec
    total = sum(node_s.values())
    print('\nwall s per node (callbacks), per simulated s:')
    for name, sec in sorted(node_s.items(), key=lambda kv: -kv[1]):
        print(f'  {name:18s} {sec:7.1f} s  {1e3 * sec / sim:6.1f} ms/sim s  '
              f'{100 * sec / total:4.0f} %')
    if prof is not None:
        print()
        pstats.Stats(prof, stream=sys.stdout).sort_stats('tottime').print_stats(args.profile)
    return 0


def sweep_speed(comps: list, args: argparse.Namespace) -> int:
    """Trials per minute of the same trials with 1 and 2 workers and on Ray (this machine)."""
    import importlib.util
    import json

    from mindgrasp_experiments.workers import run_trials

    ways: list[tuple[str, dict]] = [('1 worker', {'workers': 1}), ('2 workers', {'workers': 2})]
    if importlib.util.find_spec('ray') is not None:
        ways.append(('ray auto', {'ray': 'auto'}))
    else:
        print('Ray is not installed (pip install -e ".[cluster]"): its row is left out')
    trials = list(range(1, args.trials + 1))
    figures: dict[str, float] = {}
    records: dict[str, list] = {}
    for name, how in ways:
        wall0 = time.perf_counter()
        runs = list(run_trials(comps, trials, seed=args.seed, step_s=args.step, **how))
        wall = time.perf_counter() - wall0
        figures[name] = 60.0 * len(runs) / wall
        records[name] = sorted((r.record for r in runs), key=lambda rec: rec.trial)
        ratio = figures[name] / figures['1 worker']
        same = str(records[name]) == str(records['1 worker'])    # NaN == NaN as text
        print(f'{name:10s} {len(runs)} trials in {wall:6.1f} s: {figures[name]:5.2f} trials/min, '
              f'{ratio:4.2f}x one worker; records {"identical" if same else "DIFFER"}',
              flush=True)
    print(json.dumps({'trials': len(trials), 'trials_per_min': figures}))
    return 0


if __name__ == '__main__':
    sys.exit(main())
