"""Vision time per frame at 128x128 and 640x480, and the shape CNN's inference time.

Frames are rendered by the PyBullet simulator (set_locations scene, from the home pose and from
a closer pre-final-approach view), then timed through the same code the vision node runs:
``ColourDetector.detect`` + ``ObjectOfInterestRanker.rank`` (the "vision" figure, targets <= 3 ms
at 128x128 and <= 15 ms at 640x480), the AR overlay, and the depth CNN (preprocessing + one
forward pass, 1 CPU thread).

Run::

    .venv/bin/python benchmarks/vision.py [--frames 300] [--json]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from mindgrasp_common.resources import resource_path
from mindgrasp_vision.detector import CameraModel, ColourDetector
from mindgrasp_vision.overlay import render_overlay
from mindgrasp_vision.ranking import ObjectOfInterestRanker
from mindgrasp_vision.shape_cnn import ShapeClassifier, preprocess_depth


def _frames(width: int, height: int) -> tuple[list[tuple[np.ndarray, np.ndarray]], np.ndarray]:
    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation
    from mindgrasp_vision.dataset import CameraPlacer

    sim = Simulation(scene='set_locations', seed=0, camera=CameraConfig(width=width,
                                                                         height=height))
    try:
        frames = [sim.render_camera()]
        placer = CameraPlacer(sim)
        for distance, elevation in ((0.25, 45.0), (0.15, 60.0)):
            if placer.look_at(np.array([0.5, 0.0, 0.025]), distance, elevation):
                frames.append(sim.render_camera())
        k, _, _ = sim.camera_intrinsics()
    finally:
        sim.close()
    return frames, k


def _stats(samples: list[float]) -> dict[str, float]:
    ms = np.array(samples) * 1e3
    return {'median_ms': float(np.median(ms)), 'p95_ms': float(np.percentile(ms, 95)),
            'mean_ms': float(ms.mean())}


def bench_resolution(width: int, height: int, n: int) -> dict[str, dict[str, float]]:
    """Time detect+rank, and the overlay, over ``n`` frames of one resolution."""
    frames, k = _frames(width, height)
    detector = ColourDetector(intrinsics=CameraModel.from_k(width, height, k))
    ranker = ObjectOfInterestRanker()
    vision, overlay = [], []
    for i in range(n + 10):
        rgb, depth = frames[i % len(frames)]
        t0 = time.perf_counter()
        dets = detector.detect(rgb, depth)
        ranker.rank(dets, width, height)
        t1 = time.perf_counter()
        render_overlay(rgb, dets, ranker.focus(width, height))
        t2 = time.perf_counter()
        if i >= 10:   # warm-up frames are not counted
            vision.append(t1 - t0)
            overlay.append(t2 - t1)
    return {'vision': _stats(vision), 'overlay': _stats(overlay)}


def bench_cnn(n: int) -> dict[str, object]:
    """Time preprocessing + one forward pass of the shape CNN (batch 1, 1 thread)."""
    path = resource_path('mindgrasp_vision', 'models') / 'shape_cnn'
    if path.with_suffix('.pt').is_file():
        clf, source = ShapeClassifier.load(path, num_threads=1), str(path)
    else:   # timing does not depend on the weights
        rng = np.random.default_rng(0)
        x = rng.uniform(-1, 1, (6, 128, 128)).astype(np.float32)
        clf, source = ShapeClassifier(epochs=1).fit(x, np.arange(6) % 3), 'untrained'
    frames, _ = _frames(128, 128)
    rgb, depth = frames[-1]
    det = max(ColourDetector().detect(rgb, depth), key=lambda d: d.pixel_count)
    samples = []
    for i in range(n + 10):
        t0 = time.perf_counter()
        x = preprocess_depth(depth, det.bbox, det.mask, clf.prep)
        clf.predict_proba(x[None])
        if i >= 10:
            samples.append(time.perf_counter() - t0)
    return {'cnn': _stats(samples), 'model': source}


def main() -> None:
    """Print the figures (and one JSON line with --json)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--frames', type=int, default=300, help='timed frames per resolution')
    parser.add_argument('--json', action='store_true', help='print a JSON line at the end')
    args = parser.parse_args()
    out: dict[str, object] = {}
    for (w, h), target in (((128, 128), 3.0), ((640, 480), 15.0)):
        res = bench_resolution(w, h, args.frames)
        out[f'{w}x{h}'] = res
        v, o = res['vision'], res['overlay']
        print(f'vision {w}x{h}: detect+rank median {v["median_ms"]:.2f} ms, p95 '
              f'{v["p95_ms"]:.2f} ms (target <= {target:.0f} ms); overlay median '
              f'{o["median_ms"]:.2f} ms', flush=True)
    cnn = bench_cnn(max(50, args.frames // 3))
    out['cnn'] = cnn
    c = cnn['cnn']
    print(f'shape CNN (128x128 depth crop, 1 thread): median {c["median_ms"]:.2f} ms, p95 '
          f'{c["p95_ms"]:.2f} ms ({cnn["model"]})')
    if args.json:
        print(json.dumps(out))


if __name__ == '__main__':
    main()
