"""Grasp benchmark: success per shape over N random placements, time per grasp, vision per frame.

    ROS_DOMAIN_ID=15 .venv/bin/python benchmarks/grasp.py [--trials 30] [--seed 0] [--vision-only]

Runs the random-locations protocol through the nodes, composed in lock-step
(mindgrasp_experiments): one object per trial, 0.2-0.7 m from the base, autonomous search,
approach and grasp. Prints success per shape and overall (target >= 95 % per
shape; the paper: cube 60.5 %, cylinder 17.6 %, sphere 13.3 %), the simulated time to grasp, the
wall time per trial and the real-time factor. Then times the vision pipeline per frame on
rendered simulator frames at 128x128 and 640x480 (targets <= 3 ms and <= 15 ms), detection only
and with the shape CNN.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def grasp_figures(trials: int, seed: int) -> None:
    """The random-locations protocol through the nodes in lock-step (mindgrasp_experiments)."""
    import tempfile
    from pathlib import Path

    from mindgrasp_experiments.engine import lockstep_components
    from mindgrasp_experiments.summary import summarise
    from mindgrasp_experiments.workers import run_trials

    comps = lockstep_components('experiment', {'protocol': 'random_locations',
                                               'subject': 'autonomous', 'seed': str(seed)},
                                Path(tempfile.mkdtemp()) / 'params', log=lambda _t: None)
    wall0 = time.perf_counter()
    runs = list(run_trials(comps, range(1, trials + 1), seed=seed))
    wall = time.perf_counter() - wall0
    records = [r.record for r in runs]
    s = summarise(records)
    print(f'Grasp success over {s["trials"]} random placements (seed {seed}), through the nodes:')
    for shape, r in s['success_by_shape'].items():
        print(f'  {shape:8s} {100 * r["rate"]:5.1f} %  ({r["count"]}/{r["trials"]})')
    print(f'  overall  {100 * s["success_rate"]:5.1f} %  ({s["success_count"]}/{s["trials"]})')
    times = [r.time_to_grasp_s for r in records if r.success]
    if times:
        print(f'Time to grasp (simulated): mean {statistics.fmean(times):.1f} s, median '
              f'{statistics.median(times):.1f} s, max {max(times):.1f} s')
    sim = sum(r.sim_s for r in runs)
    print(f'Wall time per trial: {wall / len(runs):.1f} s; real-time factor {sim / wall:.2f}')


def vision_figures(frames: int = 50) -> None:
    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation
    from mindgrasp_vision.params import VisionConfig

    cfg = VisionConfig()
    try:
        classifier = cfg.load_classifier()
    except Exception:
        classifier = None
    for width, height in ((128, 128), (640, 480)):
        sim = Simulation(scene='set_locations', camera=CameraConfig(width, height))
        rgb, depth = sim.render_camera()
        sim.close()
        for label, clf in (('detect + rank', None), ('+ shape CNN', classifier)):
            if label != 'detect + rank' and clf is None:
                continue
            pipeline = cfg.build_pipeline(clf)
            pipeline.process(rgb, depth)       # warm-up
            t = []
            for _ in range(frames):
                t0 = time.perf_counter()
                pipeline.process(rgb, depth, classify=clf is not None)
                t.append(time.perf_counter() - t0)
            t_ms = 1e3 * np.array(t)
            print(f'Vision {width}x{height} {label}: median {np.median(t_ms):.2f} ms, p95 '
                  f'{np.percentile(t_ms, 95):.2f} ms per frame')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trials', type=int, default=30)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--vision-only', action='store_true')
    args = parser.parse_args()
    if not args.vision_only:
        grasp_figures(args.trials, args.seed)
    vision_figures()
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
