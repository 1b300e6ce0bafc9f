"""Largest commanded joint acceleration of the grasp controller over a few lock-step trials
(issue 31, item 7): the controller's /arm_controller/commands, tick to tick, in every state and in
state 6 (return to start) alone; speeding up and braking apart (braking is never limited: stops
and locks act at once).

    python benchmarks/arm_limits.py                         # 3 trials, oracle subject, seed 0
    python benchmarks/arm_limits.py --trials 5 --subject autonomous --seed 2

Prints figures, asserts nothing. The same trials give the same figures (lock-step, seeded).
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
from pathlib import Path

import numpy as np
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState
from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

from mindgrasp_ros import rclpy
from mindgrasp_ros.topics import ARM_COMMANDS, FSM_STATE

#: (time s, joint velocities (6,) rad/s, controller state 1..6) of every command heard
HEARD: list[tuple[float, np.ndarray, int]] = []


class CommandProbe(rclpy.node.Node):
    """Listens to the controller's velocity commands and state in the lock-step graph."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__('arm_limits_probe', **kwargs)
        self.state = 1
        self.create_subscription(Float64MultiArray, ARM_COMMANDS.name, self.command_callback,
                                 ARM_COMMANDS.qos)
        self.create_subscription(FsmState, FSM_STATE.name, self.state_callback, FSM_STATE.qos)

    def state_callback(self, msg: FsmState) -> None:
        self.state = int(msg.state)

    def command_callback(self, msg: Float64MultiArray) -> None:
        t = self.get_clock().now().nanoseconds * 1e-9
        HEARD.append((t, np.array(msg.data, dtype=float), self.state))


def accelerations(heard: list[tuple[float, np.ndarray, int]]) -> dict[str, float]:
    """Largest speed-up and braking (rad/s^2) between consecutive commands, overall and in
    state 6; a reversal counts as braking to zero and speeding up from it."""
    out = {'speed_up': 0.0, 'braking': 0.0, 'speed_up_return': 0.0, 'braking_return': 0.0}
    for (t0, v0, _s0), (t1, v1, s1) in itertools.pairwise(heard):
        dt = t1 - t0
        if dt <= 0:
            continue
        same = v0 * v1 > 0
        up = np.where(same, np.abs(v1) - np.abs(v0), np.abs(v1))
        down = np.where(same, np.abs(v0) - np.abs(v1), np.abs(v0))
        for key, value in (('speed_up', float(np.max(up)) / dt),
                           ('braking', float(np.max(down)) / dt)):
            out[key] = max(out[key], value)
            if s1 == 6:
                out[f'{key}_return'] = max(out[f'{key}_return'], value)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trials', type=int, default=3)
    parser.add_argument('--subject', default='oracle', choices=['virtual', 'oracle', 'autonomous'])
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)

    from mindgrasp_experiments.engine import lockstep_components, run_trial
    from mindgrasp_ros.graph.spec import NodeSpec

    comps = lockstep_components('experiment', {'subject': args.subject, 'seed': str(args.seed)},
                                Path(tempfile.mkdtemp()) / 'params', log=lambda _text: None)
    comps.append(NodeSpec('arm_limits_probe', f'{__name__}:CommandProbe'))
    worst = dict.fromkeys(accelerations([]), 0.0)
    for trial in range(1, args.trials + 1):
        HEARD.clear()
        run = run_trial(comps, trial, seed=args.seed, log_level='warn')
        acc = accelerations(HEARD)
        worst = {k: max(worst[k], v) for k, v in acc.items()}
        r = run.record
        print(f'trial {trial}: {r.desired:16s} success {r.success!s:5} {len(HEARD)} commands; '
              f'max speed-up {acc["speed_up"]:6.2f} rad/s^2 (return {acc["speed_up_return"]:5.2f})'
              f', max braking {acc["braking"]:6.2f} rad/s^2', flush=True)
    print(f'\n{args.trials} trials, subject {args.subject}, seed {args.seed}: largest commanded '
          f'speed-up {worst["speed_up"]:.2f} rad/s^2 ({worst["speed_up_return"]:.2f} in the '
          f'return to start), largest braking {worst["braking"]:.2f} rad/s^2 '
          f'({worst["braking_return"]:.2f} in the return)')
    return 0


if __name__ == '__main__':
    sys.exit(main())
