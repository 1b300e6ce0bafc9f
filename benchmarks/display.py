"""Participant display: time to compose and show one frame per layout, and the scene camera cost.

Frames are composed by :class:`ParticipantScreen` from a real PyBullet scene view (with the
training robot) and eye-in-hand image, then shown in the pygame window the node uses (SDL's dummy
driver: no screen needed; under a desktop the flip to a real window adds the driver's time).
The scene camera figure is :meth:`Simulation.render_scene` at the node's default size, which the
simulator pays at ``scene_camera_rate``. A frame budget of 33 ms (30 Hz) leaves room for both.

Run::

    .venv/bin/python benchmarks/display.py [--frames 200] [--width 1024 --height 600] [--json]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from mindgrasp_sim.simulation import Simulation
from mindgrasp_trainer.protocol import PromptEvent
from mindgrasp_trainer.screen import ParticipantScreen, ScreenState
from mindgrasp_trainer.window import Window


def _ms(samples: list[float]) -> dict[str, float]:
    a = np.asarray(samples) * 1e3
    return {'median_ms': round(float(np.median(a)), 3),
            'p95_ms': round(float(np.percentile(a, 95)), 3)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--frames', type=int, default=200)
    parser.add_argument('--width', type=int, default=1024)
    parser.add_argument('--height', type=int, default=600)
    parser.add_argument('--json', action='store_true')
    args = parser.parse_args()

    with Simulation('set_locations', trainer_robot=True) as sim:
        sim.set_joint_velocities(np.array([0.5, 0.1, 0, 0, 0, 0]), robot='trainer')
        sim.step(240)
        scene_times = []
        for _ in range(20):
            t = time.perf_counter()
            scene = sim.render_scene(320, 240)
            scene_times.append(time.perf_counter() - t)
        camera, _ = sim.render_camera()

    window = Window(args.width, args.height, headless=True)
    states = {
        'graz': ScreenState(prompt=PromptEvent(0.0, 'move', 3, 1, 2.75, 'graz'),
                            prediction=(1, 0.6), n_trials=40),
        'trainer': ScreenState(prompt=PromptEvent(0.0, 'move', 3, 0, 2.0, 'trainer'),
                               scene=scene, camera=camera, ee_distance=0.08,
                               prediction=(0, 0.4), fsm_state_name='Object Search'),
        'test': ScreenState(scene=scene, camera=camera, target='red cube', target_trial=2,
                            n_trials=20, prediction=(2, 0.5), fsm_state_name='Center Object'),
    }
    results: dict[str, dict] = {'scene_camera_320x240': _ms(scene_times)}
    for layout, state in states.items():
        screen = ParticipantScreen(args.width, args.height, layout=layout)
        compose, show = [], []
        for _ in range(args.frames):
            t0 = time.perf_counter()
            frame = screen.render(state)
            t1 = time.perf_counter()
            window.show(frame)
            t2 = time.perf_counter()
            compose.append(t1 - t0)
            show.append(t2 - t1)
        results[layout] = {'compose': _ms(compose), 'show': _ms(show)}
    window.close()

    if args.json:
        print(json.dumps(results))
        return
    s = results['scene_camera_320x240']
    print(f"scene camera 320x240 (both robots, 2 renders): median {s['median_ms']:.1f} ms, "
          f"p95 {s['p95_ms']:.1f} ms")
    print(f'{args.width}x{args.height} frame, {args.frames} frames per layout:')
    print(f"  {'layout':<8} {'compose median':>15} {'p95':>8} {'show median':>12} {'p95':>8}")
    for layout in states:
        c, w = results[layout]['compose'], results[layout]['show']
        print(f"  {layout:<8} {c['median_ms']:>12.2f} ms {c['p95_ms']:>5.2f} ms "
              f"{w['median_ms']:>9.2f} ms {w['p95_ms']:>5.2f} ms")


if __name__ == '__main__':
    main()
