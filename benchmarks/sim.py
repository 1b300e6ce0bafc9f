"""Speed of the PyBullet simulation in fast mode (as fast as it can, as the node runs it).

Prints, per camera setting, the real-time factor (simulated s per wall s, and per CPU s of this
process, which a busy shared machine distorts less) of the node's fast-mode work per simulated
second (240 physics steps, joint states read at 100 Hz, the RGB-D camera
rendered at its rate, the arm moving), plus the mean physics step time and render time.

    .venv/bin/python benchmarks/sim.py [--seconds 10] [--node] [--grasps 40]

``--grasps N`` also grasps every object of N random-locations layouts with the scripted top-down
grasp (cube yaw unknown to the grasp) and prints the success rate per shape.

``--node`` also runs ``python -m mindgrasp_sim.sim_node`` in fast mode as its own process and
reports its real-time factor from the node's own statistics (ROS layer and DDS included).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time

import numpy as np

from mindgrasp_sim.camera import CameraConfig
from mindgrasp_sim.simulation import Simulation

SETTINGS = ((128, 128, 10.0), (640, 480, 30.0))


def run_core(width: int, height: int, rate: float, seconds: float) -> dict[str, float]:
    """Fast-mode loop on the ROS-free Simulation; returns the figures."""
    sim = Simulation('set_locations', seed=0, camera=CameraConfig(width, height, rate))
    steps = int(seconds * sim.physics_hz)
    js_every = round(sim.physics_hz / 100.0)
    cam_every = round(sim.physics_hz / rate)
    step_t = render_t = 0.0
    n_render = 0
    rng = np.random.default_rng(0)
    t0, c0 = time.perf_counter(), time.process_time()
    for i in range(steps):
        if i % 120 == 0:   # a controller changing its command twice a second
            sim.set_joint_velocities(rng.uniform(-0.2, 0.2, 6))
        a = time.perf_counter()
        sim.step()
        b = time.perf_counter()
        step_t += b - a
        if i % js_every == 0:
            sim.joint_positions()
            sim.joint_velocities()
            sim.ee_pose()
        if i % cam_every == 0:
            sim.render_camera()
            render_t += time.perf_counter() - b
            n_render += 1
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    sim.close()
    return {'rtf': seconds / wall, 'rtf_cpu': seconds / cpu, 'step_ms': 1e3 * step_t / steps,
            'render_ms': 1e3 * render_t / max(n_render, 1)}


def run_node(width: int, height: int, rate: float, seconds: float
             ) -> tuple[float, float] | None:
    """Sim node in fast mode as its own process; its reported real-time factors (wall, CPU)."""
    env = dict(os.environ)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    cmd = [sys.executable, '-m', 'mindgrasp_sim.sim_node', '--ros-args',
           '-p', 'time_mode:=fast', '-p', f'sim_duration:={seconds}',
           '-p', f'camera_width:={width}', '-p', f'camera_height:={height}',
           '-p', f'camera_rate:={rate}']
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600)
    found = re.search(r'real-time factor ([0-9.]+)x \(([0-9.]+)x per CPU',
                      out.stdout + out.stderr)
    return (float(found.group(1)), float(found.group(2))) if found else None


def run_grasps(n_layouts: int) -> dict[str, list[bool]]:
    """Scripted grasp of each object of ``n_layouts`` random layouts; success per shape."""
    import math

    from mindgrasp_sim import scripted

    # a controller does not know the cube's yaw: grasp along the bearing from the base
    scripted.grasp_yaw = lambda obj: math.atan2(obj.position[1], obj.position[0])
    results: dict[str, list[bool]] = {}
    with Simulation('random_locations', seed=0) as sim:
        for seed in range(n_layouts):
            sim.reset(seed=seed)
            for obj in sim.objects():
                sim.reset()
                out = scripted.grasp_object_at(sim, obj)
                results.setdefault(obj.shape, []).append(out.success)
    return results


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=10.0, help='simulated seconds per run')
    parser.add_argument('--node', action='store_true', help='also benchmark the node process')
    parser.add_argument('--grasps', type=int, default=0,
                        help='also run scripted grasps on this many random layouts')
    args = parser.parse_args()
    load = os.getloadavg()[0] if hasattr(os, 'getloadavg') else float('nan')
    print(f'fast mode, {args.seconds:.0f} simulated s per run, physics 240 Hz, '
          f'{os.cpu_count()} CPUs, load average {load:.1f} at start')
    header = ('| camera | real-time factor (wall) | per CPU second | step time (ms) | '
              'render time (ms) |')
    if args.node:
        header += ' node process (DDS), wall / CPU |'
    print(header)
    print('|' + '|'.join(['---'] * (header.count('|') - 1)) + '|')
    for w, h, r in SETTINGS:
        res = run_core(w, h, r, args.seconds)
        row = (f'| {w}x{h} @ {r:.0f} Hz | {res["rtf"]:.1f}x | {res["rtf_cpu"]:.1f}x | '
               f'{res["step_ms"]:.3f} | {res["render_ms"]:.2f} |')
        if args.node:
            rtf = run_node(w, h, r, args.seconds)
            row += f' {rtf[0]:.1f}x / {rtf[1]:.1f}x |' if rtf is not None else ' n/a |'
        print(row, flush=True)
    if args.grasps:
        print(f'\nscripted top-down grasps, {args.grasps} random layouts '
              '(radius 0.2-0.7 m, 4-6 cm)')
        print('| shape | lifted > 0.22 m |')
        print('|---|---|')
        for shape, ok in run_grasps(args.grasps).items():
            print(f'| {shape} | {sum(ok)}/{len(ok)} ({100 * sum(ok) / len(ok):.0f} %) |')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
