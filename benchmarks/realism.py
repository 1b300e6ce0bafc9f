"""Realism benchmark: grasp success per shape with the realism profile off and on, and sweeps of
single realism factors.

    python benchmarks/realism.py compare [--trials 90] [--seed 0] [--workers 2] [--profile default]
    python benchmarks/realism.py sweep [--trials 30] [--seed 0] [--workers 2] [--plot sweep.png]
    python benchmarks/realism.py cnn [--images 150] [--model my_models/shape_cnn]

``compare`` runs the random-locations protocol (one object per trial, random shape, colour, size,
0.2-0.7 m from the base, autonomous search, approach and grasp) twice on the same placements:
with a perfect world and with the realism profile (mindgrasp_sim.realism: depth noise and invalid
pixels, colour noise and lighting, camera mount error, encoder noise and velocity lag, object
spread, contacts on any surface). Prints success per shape for each (target >= 95 % per shape
with the default profile) and a plot of both (``--plot``).

``sweep`` varies one factor at a time on top of the profile: the depth noise std x1, x2, x4 and
the camera mount error (max offset / max rotation) 0 / 0.5 cm 1 deg / 1 cm 1.5 deg / 2 cm 3 deg,
and prints a table of the success rates (plot with ``--plot``).

``cnn`` measures the depth shape CNN's accuracy on simulator views collected with the realism
profile and without it (independent images, seed + 1000 as ``mindgrasp train vision`` uses).

Each trial runs through the nodes composed in lock-step (mindgrasp_experiments.engine: the
experiment profile's simulator, vision and controller nodes on simulated time); trials are spread
over ``--workers`` processes and seeded by the trial index, so the figures do not depend on the
number of workers. The last line is one JSON object.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

SHAPES = ('cube', 'cylinder', 'sphere')


def _run_chunk(profile: dict | None, seed: int, n_trials: int, indices: list[int],
               timeout: float) -> list[dict]:
    """Worker: run the random-locations trials ``indices`` (0-based) through the nodes in
    lock-step (mindgrasp_experiments) with a profile (as a dict; None = no realism). Returns one
    record per trial."""
    import tempfile
    from pathlib import Path

    import yaml

    from mindgrasp_experiments.engine import lockstep_components, run_trial
    from mindgrasp_experiments.protocols import random_locations_trial

    work = Path(tempfile.mkdtemp(prefix='realism_'))
    realism = 'none'
    if profile is not None:
        realism = str(work / 'profile.yaml')
        Path(realism).write_text(yaml.safe_dump(profile), encoding='utf-8')
    comps = lockstep_components('experiment', {'protocol': 'random_locations',
                                               'subject': 'autonomous', 'seed': str(seed),
                                               'realism': realism}, work / 'params',
                                log=lambda _t: None)
    for comp in comps:
        if comp.module.endswith('trial_manager_node'):
            comp.ros_args += ['-p', f'trial_timeout:={timeout}']
    out = []
    for i in indices:
        spec = random_locations_trial(seed, i + 1)
        run = run_trial(comps, i + 1, seed=seed, log_level='warn')
        rec = run.record
        out.append({'index': i, 'shape': spec.shape, 'success': bool(rec.success),
                    'time_to_grasp': rec.time_to_grasp_s,
                    'attempts': rec.states.split('-').count('5'),
                    'detected_shape': rec.chosen.rpartition(' ')[2] or 'unknown',
                    'reason': rec.reason, 'wall_s': run.wall_s, 'radius': spec.radius,
                    'angle_deg': spec.angle_deg})
        print(f'    [{profile["name"] if profile else "off"}] trial {i}: {spec.shape} '
              f'{"grasped" if rec.success else "FAILED"} ({run.wall_s:.0f} s wall)', flush=True)
    return out


def _profile_dict(profile: object) -> dict:
    data = dataclasses.asdict(profile)
    return {k: ({f: list(v) if isinstance(v, tuple) else v for f, v in val.items()}
                if isinstance(val, dict) else val) for k, val in data.items()}


def run_condition(profile: object | None, trials: int, seed: int, workers: int,
                  timeout: float) -> list[dict]:
    """All trials of one condition, spread over ``workers`` processes."""
    data = None if profile is None else _profile_dict(profile)
    chunks = [list(range(k, trials, workers)) for k in range(workers)]
    chunks = [c for c in chunks if c]
    if len(chunks) == 1:
        records = _run_chunk(data, seed, trials, chunks[0], timeout)
    else:
        with ProcessPoolExecutor(len(chunks), mp_context=get_context('spawn')) as pool:
            futures = [pool.submit(_run_chunk, data, seed, trials, c, timeout) for c in chunks]
            records = [r for f in futures for r in f.result()]
    return sorted(records, key=lambda r: r['index'])


def by_shape(records: list[dict]) -> dict[str, tuple[int, int]]:
    """shape -> (successes, trials)."""
    return {s: (sum(r['success'] for r in records if r['shape'] == s),
                sum(r['shape'] == s for r in records)) for s in SHAPES}


def _pct(k: int, n: int) -> str:
    return f'{100 * k / n:5.1f} % ({k:2d}/{n:2d})' if n else '   n/a        '


def _failures(name: str, records: list[dict]) -> None:
    for r in records:
        if not r['success']:
            print(f'  {name} trial {r["index"]}: {r["shape"]} r {r["radius"]:.2f} m '
                  f'{r["angle_deg"]:+.0f} deg, seen as {r["detected_shape"]}: {r["reason"]}')


def compare(args: argparse.Namespace) -> dict:
    from mindgrasp_sim.realism import RealismProfile

    profile = RealismProfile.load(args.profile)
    t0 = time.perf_counter()
    # realism first: the perfect world's figure is the known one
    on = run_condition(profile, args.trials, args.seed, args.workers, args.timeout)
    s = by_shape(on)
    print(f"Realism '{profile.name}': " + ', '.join(f'{k} {_pct(*s[k])}' for k in SHAPES),
          flush=True)
    off = [] if args.skip_off else run_condition(None, args.trials, args.seed, args.workers,
                                                 args.timeout)
    wall = time.perf_counter() - t0
    s_off, s_on = by_shape(off), by_shape(on)
    print(f'Grasp success, random locations, {args.trials} trials each (seed {args.seed}), '
          f"realism off vs profile '{profile.name}':")
    print(f'  {"shape":9s} {"off":18s} {profile.name}')
    for s in SHAPES:
        print(f'  {s:9s} {_pct(*s_off[s])}  {_pct(*s_on[s])}')
    tot = [sum(r['success'] for r in rs) for rs in (off, on)]
    print(f'  {"overall":9s} {_pct(tot[0], len(off))}  {_pct(tot[1], len(on))}')
    ok = [r['time_to_grasp'] for r in on if r['success'] and math.isfinite(r['time_to_grasp'])]
    if ok:
        print(f'Time to grasp with realism (simulated): median {sorted(ok)[len(ok) // 2]:.1f} s')
    print(f'Wall time {wall:.0f} s for {2 * args.trials} trials on {args.workers} worker(s).')
    _failures('off', off)
    _failures(profile.name, on)
    if args.plot:
        _plot_compare(args.plot, s_off, s_on, profile.name, args.trials)
    return {'mode': 'compare', 'profile': profile.name, 'trials': args.trials,
            'seed': args.seed, 'off': s_off, 'on': s_on, 'wall_time_s': wall,
            'records_on': on, 'records_off': off}


def sweep_levels(profile: object) -> list[tuple[str, str, object]]:
    """(factor, level label, profile) of the one-factor sweeps."""
    from mindgrasp_sim.realism import CameraMountError

    levels = [('depth noise', f'x{k:g}', profile.scaled(depth=k)) for k in (1.0, 2.0, 4.0)]
    for cm, deg in ((0.0, 0.0), (0.5, 1.0), (1.0, 1.5), (2.0, 3.0)):
        mount = CameraMountError(max_offset=cm / 100.0, max_angle_deg=deg)
        levels.append(('camera mount', f'{cm:g} cm / {deg:g} deg',
                       dataclasses.replace(profile, camera_mount=mount)))
    return levels


def _records_from_lines(lines: list[str], name: str) -> list[dict]:
    """Trial records from the per-trial lines of a run (``[name] trial i: shape grasped``)."""
    out = []
    for line in lines:
        parts = line.split()
        if len(parts) >= 5 and parts[0] == f'[{name}]' and parts[1] == 'trial':
            out.append({'index': int(parts[2].rstrip(':')), 'shape': parts[3],
                        'success': parts[4] == 'grasped'})
    return out


def sweep(args: argparse.Namespace) -> dict:
    from mindgrasp_sim.realism import RealismProfile

    profile = RealismProfile.load(args.profile)
    rows = []
    t0 = time.perf_counter()
    done: dict[object, list[dict]] = {}
    if args.reuse:
        # the profile's own level from a compare run: same seed, same first trials, same code
        with open(args.reuse, encoding='utf-8') as f:
            text = f.read().strip().splitlines()
        prior = json.loads(text[-1])
        if prior.get('seed') != args.seed or prior.get('profile') != profile.name:
            print(f'realism.py: --reuse {args.reuse} ran seed {prior.get("seed")} profile '
                  f'{prior.get("profile")}; run it with this --seed and --profile.',
                  file=sys.stderr)
            raise SystemExit(2)
        records = prior.get('records_on') or _records_from_lines(text, profile.name)
        # the same placements only when the compare run drew as many trials (the shapes are
        # shuffled over all of them)
        if len(records) == args.trials:
            done[json.dumps(_profile_dict(profile), sort_keys=True)] = records
    for factor, label, p in sweep_levels(profile):
        key = json.dumps(_profile_dict(p), sort_keys=True)
        if key not in done:     # x1 and the profile's own mount error are the same runs
            done[key] = run_condition(p, args.trials, args.seed, args.workers, args.timeout)
        records = done[key]
        rows.append((factor, label, by_shape(records),
                     sum(r['success'] for r in records), len(records)))
        print(f'  {factor:13s} {label:18s} ' + '  '.join(
            f'{s} {_pct(*rows[-1][2][s])}' for s in SHAPES)
            + f'  all {_pct(rows[-1][3], rows[-1][4])}', flush=True)
    wall = time.perf_counter() - t0
    print(f"One-factor sweeps on profile '{profile.name}', {args.trials} trials per level "
          f'(seed {args.seed}), {wall:.0f} s wall time.')
    if args.plot:
        _plot_sweep(args.plot, rows, profile.name, args.trials)
    return {'mode': 'sweep', 'profile': profile.name, 'trials': args.trials, 'seed': args.seed,
            'rows': [{'factor': f, 'level': lvl, 'by_shape': b, 'successes': k, 'trials': n}
                     for f, lvl, b, k, n in rows], 'wall_time_s': wall}


def cnn(args: argparse.Namespace) -> dict:
    import numpy as np

    from mindgrasp_sim.realism import RealismProfile
    from mindgrasp_vision.dataset import collect_shape_dataset
    from mindgrasp_vision.params import DEFAULT_SHAPE_MODEL
    from mindgrasp_vision.shape_cnn import SHAPES as CNN_SHAPES
    from mindgrasp_vision.shape_cnn import ShapeClassifier

    model = args.model or DEFAULT_SHAPE_MODEL
    clf = ShapeClassifier.load(model)
    profile = RealismProfile.load(args.profile)
    out = {'mode': 'cnn', 'model': model, 'images': args.images, 'seed': args.seed + 1000}
    conditions = [(profile.name, profile)] + ([] if args.skip_off else [('none', None)])
    for name, realism in conditions:
        t0 = time.perf_counter()
        data = collect_shape_dataset(args.images, seed=args.seed + 1000, realism=realism)
        pred = clf.predict_proba(data.x).argmax(1)
        acc = float(np.mean(pred == data.y))
        per = {s: float(np.mean(pred[data.y == i] == i)) for i, s in enumerate(CNN_SHAPES)}
        out[name] = {'accuracy': acc, 'by_shape': per}
        print(f'Shape CNN {model} on {args.images} views, realism {name}: {100 * acc:.1f} % ('
              + ', '.join(f'{s} {100 * a:.1f} %' for s, a in per.items())
              + f'); {time.perf_counter() - t0:.0f} s', flush=True)
    return out


def _plot_compare(path: str, s_off: dict, s_on: dict, name: str, trials: int) -> None:
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2))
    x = range(len(SHAPES))
    for k, (label, s) in enumerate((('realism off', s_off), (f'realism {name}', s_on))):
        ax.bar([i + (k - 0.5) * 0.38 for i in x],
               [100 * s[sh][0] / max(s[sh][1], 1) for sh in SHAPES], 0.36, label=label)
    ax.axhline(95, color='k', lw=0.8, ls='--', label='target 95 %')
    ax.set_xticks(list(x), SHAPES)
    ax.set_ylim(0, 105)
    ax.set_ylabel('grasp success (%)')
    ax.set_title(f'Random locations, {trials} trials per condition')
    ax.legend(loc='lower right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f'Plot: {path}')


def _plot_sweep(path: str, rows: list, name: str, trials: int) -> None:
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    factors = list(dict.fromkeys(r[0] for r in rows))
    fig, axes = plt.subplots(1, len(factors), figsize=(4.5 * len(factors), 3.2), sharey=True)
    for ax, factor in zip(axes, factors, strict=True):
        sel = [r for r in rows if r[0] == factor]
        labels = [r[1] for r in sel]
        for s in SHAPES:
            ax.plot(labels, [100 * r[2][s][0] / max(r[2][s][1], 1) for r in sel], 'o-', label=s)
        ax.plot(labels, [100 * r[3] / max(r[4], 1) for r in sel], 'k^--', label='all')
        ax.axhline(95, color='grey', lw=0.8, ls=':')
        ax.set_title(f'{factor} (rest: {name})')
        ax.set_ylim(0, 105)
        ax.tick_params(axis='x', labelsize=8)
    axes[0].set_ylabel('grasp success (%)')
    axes[0].legend(fontsize=8, loc='lower left')
    fig.suptitle(f'One factor at a time, {trials} trials per level', fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f'Plot: {path}')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('mode', choices=('compare', 'sweep', 'cnn'))
    parser.add_argument('--trials', type=int, default=None,
                        help='trials per condition (default 90 compare, 30 sweep)')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--workers', type=int, default=1)
    parser.add_argument('--profile', default='default', help='realism profile name or YAML path')
    parser.add_argument('--timeout', type=float, default=120.0, help='simulated s per trial')
    parser.add_argument('--plot', default='', help='write a PNG plot here')
    parser.add_argument('--images', type=int, default=150, help='cnn: test views per condition')
    parser.add_argument('--reuse', default='',
                        help="sweep: a compare run's output (same --trials, --seed, --profile) "
                             "whose realism trials stand for the profile's own level")
    parser.add_argument('--skip-off', action='store_true',
                        help='compare, cnn: run the realism condition only')
    parser.add_argument('--model', default='', help='cnn: shape model (default the vision one)')
    args = parser.parse_args()
    if args.trials is None:
        args.trials = 90 if args.mode == 'compare' else 30
    if args.trials < 1 or args.workers < 1:
        print('realism.py: --trials and --workers must be >= 1.', file=sys.stderr)
        return 2
    summary = {'compare': compare, 'sweep': sweep, 'cnn': cnn}[args.mode](args)
    print(json.dumps(summary))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
