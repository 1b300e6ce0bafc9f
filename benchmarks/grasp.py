"""Grasp benchmark: success per shape over N random placements, time per grasp, vision per frame.

    ROS_DOMAIN_ID=15 .venv/bin/python benchmarks/grasp.py [--trials 30] [--seed 0] [--vision-only]

Runs the random-locations protocol in-process and in lock-step (the same Simulation,
VisionPipeline and GraspFsm the nodes use): one object per trial, 0.2-0.7 m from the base,
autonomous search, approach and grasp. Prints success per shape and overall (target >= 95 % per
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
    from mindgrasp_fsm.experiment import run_random_locations
    from mindgrasp_fsm.params import FsmParams, default_params_path

    params = FsmParams.from_yaml(default_params_path())
    summary = run_random_locations(trials, seed, params)
    print(f'Grasp success over {summary["trials"]} random placements (seed {seed}, shape model '
          f'{summary["shape_model"]}):')
    for shape, rate in summary['success_by_shape'].items():
        c = summary['counts_by_shape'][shape]
        print(f'  {shape:8s} {100 * rate:5.1f} %  ({c["successes"]}/{c["trials"]})')
    print(f'  overall  {100 * summary["success_rate"]:5.1f} %  '
          f'({summary["successes"]}/{summary["trials"]})')
    times = [r['time_to_grasp'] for r in summary['results'] if r['success']]
    if times:
        print(f'Time to grasp (simulated): mean {statistics.fmean(times):.1f} s, median '
              f'{statistics.median(times):.1f} s, max {max(times):.1f} s')
    print(f'Wall time per trial: {summary["wall_time_s"] / summary["trials"]:.1f} s; '
          f'real-time factor {summary["real_time_factor"]:.2f}')
    print(f'Vision in the loop: {summary["vision_ms_per_frame"]:.2f} ms per frame '
          f'(128x128, shape CNN while approaching)')
    if not np.isnan(summary['shape_accuracy']):
        print(f'Shape classification at the final approach: {100 * summary["shape_accuracy"]:.1f}'
              ' % correct')


def vision_figures(frames: int = 50) -> None:
    from mindgrasp_sim.simulation import CameraConfig, Simulation
    from mindgrasp_vision.config import VisionConfig

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
