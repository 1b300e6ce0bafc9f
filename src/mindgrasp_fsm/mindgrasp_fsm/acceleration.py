"""Acceleration limits for joint velocity commands (ROS-free).

One :class:`AccelerationLimiter` sits on every velocity output of the controller, so that no
profile (search sweep, centring, approach, grasp policy, lift, return to start) can step a joint
from slow to fast in one control tick. Speeding up is limited per joint; slowing down towards
zero is not: a stop, a lock between states or a joint-limit clamp must take effect at once.
"""

from __future__ import annotations

import numpy as np


class AccelerationLimiter:
    """Limit how fast each joint's commanded velocity may grow.

    Call :meth:`limit` once per control tick with the wanted velocities; it returns the command
    to send and remembers it as the previous one. A wanted velocity of the other sign first
    brakes to zero (at once) and then ramps up from there.
    """

    def __init__(self, n_joints: int = 6) -> None:
        self.previous = np.zeros(n_joints)

    def reset(self) -> None:
        """Forget the previous command (the arm is at rest)."""
        self.previous = np.zeros_like(self.previous)

    def limit(self, wanted: np.ndarray, dt: float, acceleration: np.ndarray | float
              ) -> np.ndarray:
        """Velocities (n_joints,) rad/s to command this tick.

        Parameters
        ----------
        wanted : ndarray, shape (n_joints,)
            Velocities the controller asks for (rad/s).
        dt : float
            Time since the previous tick (s); 0 allows no speeding up.
        acceleration : ndarray, shape (n_joints,), or float
            Largest speed-up per joint (rad/s^2).
        """
        wanted = np.asarray(wanted, dtype=float)
        step = np.asarray(acceleration, dtype=float) * max(float(dt), 0.0)
        prev = self.previous
        # a reversal brakes to zero first: the ramp starts from rest on the new side
        base = np.where(prev * wanted > 0.0, np.abs(prev), 0.0)
        speed = np.minimum(np.abs(wanted), base + step)
        out = np.sign(wanted) * speed
        self.previous = out
        return out


__all__ = ['AccelerationLimiter']
