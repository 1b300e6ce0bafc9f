"""How far below its goal the straight descent ends when the controller's ticks come late and
its joint states are old (issue 28: on a starved machine the live demo stopped 3 mm low and the
open fingertips stuck on the table).

    python benchmarks/descent_late_ticks.py                  # the shipped arm
    python benchmarks/descent_late_ticks.py --robot panda

A model, not the node graph: the controller's own grasp policy (``GraspPolicy``, its URDF
kinematics) plans the pre-grasp above a cube 0.46 m from the base and runs its descent against
a kinematic arm that does what a velocity driver does (the last command runs until the next one,
or zero after the driver's ``command_timeout``; a 50 ms first-order velocity lag as in the
realism profile). The controller sees the joint state of ``stale`` s ago, and 30 % of its ticks
come ``late`` s after the last one instead of 20 ms (a seeded draw). Printed: where the tool
ends and its lowest point, in mm above (+) or below (-) the grasp height. No table: the figure
is how far the command carries the tool, not where a table would stop it.
"""

from __future__ import annotations

import argparse

import numpy as np

from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams


def descend(fsm: GraspFsm, late: float, stale: float, command_timeout: float = 0.25,
            lag: float = 0.05, seed: int = 0) -> tuple[float, float, float]:
    """(end, lowest) tool height relative to the grasp height (m) after an 8 s descent, and
    the time (s) the policy took to say it is at the grasp height (inf: never)."""
    fsm.reset()                                  # a new policy: no commands sent yet
    policy, kin = fsm.policy, fsm.kinematics
    rng = np.random.default_rng(seed)
    policy.begin_approach(0.0, 'cube', 0)
    policy.object_position = np.array([0.45, 0.1, 0.025])
    q = np.array(fsm.params.home_position, dtype=float)
    if policy._plan_pregrasp(q):
        msg = 'no pre-grasp pose for the test cube'
        raise SystemExit(msg)
    q = policy._q_target.copy()
    policy._begin_descend(0.0, q)
    goal_z = float(policy._line[1][2])
    step = 1 / 240                               # s, the simulator's physics step
    history = [(0.0, q.copy(), np.zeros_like(q))]
    command, commanded_at, next_tick, done = np.zeros_like(q), 0.0, 0.0, False
    velocity, lowest, t, done_at = np.zeros_like(q), np.inf, 0.0, np.inf
    while t < 8.0:
        if t >= next_tick:
            seen_at, seen, seen_v = [h for h in history if h[0] <= max(t - stale, 0.0)][-1]
            command = np.zeros_like(q)
            if not done:
                policy.observe(t, seen_at, seen_v)         # as GraspFsm.tick does
                v, done, failed = policy._follow_line(t, seen)
                done = done or failed
                done_at = t if done else done_at
                command = np.zeros_like(q) if done else v
            policy.sent(t, command)                # as GraspFsm._output does
            commanded_at = t
            next_tick = t + (late if rng.random() < 0.3 else fsm.params.control_period)
        target = command if t - commanded_at <= command_timeout else np.zeros_like(q)
        velocity = velocity + (target - velocity) * (step / lag)
        q = q + velocity * step
        t += step
        history.append((t, q.copy(), velocity.copy()))
        lowest = min(lowest, float(kin.tool_position(q)[2]))
    return float(kin.tool_position(q)[2]) - goal_z, lowest - goal_z, done_at


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--robot', default='mindgrasp_arm', help='robot description name')
    args = parser.parse_args()
    fsm = GraspFsm.from_params(FsmParams(robot=args.robot))
    for late in (0.02, 0.1, 0.2, 0.3):
        for stale in (0.0, 0.05, 0.1, 0.2):
            end, lowest, took = descend(fsm, late, stale)
            print(f'ticks late {late:.2f} s, joint states {stale:.2f} s old: ends '
                  f'{1000 * end:+.1f} mm, lowest {1000 * lowest:+.1f} mm, descent '
                  f'{took:.2f} s')


if __name__ == '__main__':
    main()
