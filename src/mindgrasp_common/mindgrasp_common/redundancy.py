"""Redundancy resolution for seven-joint arms (ROS-free, shared by the controller's grasp IK and
the simulator's MoveIt-Servo-like twist input).

A pose of the tool fixes six numbers; a seven-joint arm (the Franka Panda, a KUKA LWR) has one
joint more, so a one-dimensional family of joint motions (the Jacobian's null space) leaves the
tool where it is. Left alone, damped least squares lets the elbow drift along it over a long
motion, into a joint limit. This module spends that motion on a secondary task: back towards the
home pose, harder for joints close to a limit. A six-joint arm has no null space: the step is
zero and its kinematics compute exactly as before.
"""

from __future__ import annotations

import numpy as np

__all__ = ['redundancy_step']


def redundancy_step(jac: np.ndarray, q: np.ndarray, q_home: np.ndarray, lower: np.ndarray,
                    upper: np.ndarray, gain: float = 0.5) -> np.ndarray:
    """Joint step (n,) rad (or rad/s) in the null space of ``jac`` (6, n) that moves the joints
    ``q`` (n,) rad towards ``q_home`` (n,) rad, each joint weighted up near its limits
    ``lower``/``upper`` (n,) rad, all but joint 1 (the base yaw, which faces the task); zero for
    a six-joint arm (no null space).

    The projection is onto the exact null space (the right singular vectors of ``jac`` beyond
    its rank), so the step moves the tool not at all and an IK that adds it to its task step
    converges as it would without it (a projector built from the damped pseudo-inverse leaked
    ~1 mm per step into the task: the Panda's IK never met its 0.2 mm tolerance and ran all
    its 100 iterations, 24 ms a call against 0.5 ms). The secondary objective is the gradient
    of ``sum(w_i (q_i - home_i)^2) / 2`` with ``w_i`` growing as ``1 / (distance to the nearer
    limit)``, so a joint close to a limit is pulled back harder than one at mid-range.
    """
    n = jac.shape[1]
    if n <= 6:
        return np.zeros(n)
    span = np.maximum(upper - lower, 1e-6)
    room = np.maximum(np.minimum(q - lower, upper - q) / span, 0.02)   # 0 at a limit, 0.5 mid
    pull = (q_home - q) * (0.5 / room)
    # joint 1 turns the arm towards the task (the controller's search and turns drive it;
    # objects lie all round): pulled to home, it swung a grasp behind the base over the
    # shoulder, with joints 3 and 5 turned half round
    pull[0] = 0.0
    _, sv, vt = np.linalg.svd(jac)
    rank = int(np.sum(sv > 1e-9 * max(float(sv[0]), 1e-300)))
    null = vt[rank:]                                          # (n - rank, n)
    return gain * (null.T @ (null @ pull))
