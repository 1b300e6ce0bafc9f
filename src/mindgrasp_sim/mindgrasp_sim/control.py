"""Command handling shared by the node and tests (ROS-free): validation of joint velocity and
gripper commands and the command timeout of a forward velocity controller."""

from __future__ import annotations

import math

import numpy as np

from mindgrasp_sim.errors import SimError


def validate_velocities(values: object, n_joints: int = 6) -> np.ndarray:
    """A velocity command as a float array (n_joints,) rad/s; SimError naming the problem for a
    wrong length or NaN/inf."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size != n_joints:
        msg = (f'Joint velocity command has {v.size} values but the arm has {n_joints} joints; '
               f'send {n_joints} velocities in rad/s (joint_1 .. joint_{n_joints}).')
        raise SimError(msg)
    if not np.isfinite(v).all():
        msg = f'Joint velocity command contains NaN or inf ({v.tolist()}); send finite ' \
              'velocities in rad/s.'
        raise SimError(msg)
    return v


def gripper_closure(values: object) -> float:
    """Closure 0 (open) .. 1 (closed) from a gripper command: ``[c]`` (one closure for all
    fingers) or ``[c_thumb, c_left, c_right]`` finger targets (their mean is used: the fingers
    share one force-limited actuation, like the Jaco's). SimError for empty or NaN input."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size not in (1, 3):
        msg = (f'Gripper command has {v.size} values; send [closure] with 0 = open and '
               '1 = closed, or three finger closures [thumb, left, right].')
        raise SimError(msg)
    if not np.isfinite(v).all():
        msg = f'Gripper command contains NaN or inf ({v.tolist()}); send closures in [0, 1].'
        raise SimError(msg)
    # Python floats: numpy's mean and clip wrappers cost more than the sum of three numbers
    return min(max(sum(v.tolist()) / v.size, 0.0), 1.0)


class CommandGate:
    """Holds the latest velocity command and drops it to zero when it is older than
    ``timeout`` seconds (a silent controller must not leave the arm moving).

    Times are in seconds on any monotonic clock (the node uses its ROS clock).
    """

    def __init__(self, timeout: float = 0.25, n_joints: int = 6) -> None:
        if not (math.isfinite(timeout) and timeout > 0):
            msg = f'Command timeout must be a positive number of seconds, got {timeout!r}; ' \
                  'use e.g. 0.25.'
            raise SimError(msg)
        self.timeout = float(timeout)
        self.n_joints = n_joints
        self._zeros = _read_only(np.zeros(n_joints))
        self._cmd = self._zeros
        self._stamp = -math.inf
        self.timed_out = True

    def command(self, values: object, now: float) -> np.ndarray:
        """Accept a command at time ``now`` (s); raises SimError (command ignored) if invalid."""
        self._cmd = _read_only(validate_velocities(values, self.n_joints).copy())
        self._stamp = now
        self.timed_out = False
        return self._cmd

    def current(self, now: float) -> np.ndarray:
        """The command in force at ``now`` (s): the latest one, or zeros after the timeout.

        Read-only, and the same object until the command changes (the simulator checks it every
        physics step: ``is`` instead of an element-wise comparison)."""
        if now - self._stamp > self.timeout:
            self.timed_out = True
            return self._zeros
        return self._cmd

    def shift(self, seconds: float) -> None:
        """Move the command's time by ``seconds`` (s): when the clock skips ahead, a command that
        was fresh before the skip stays as fresh after it."""
        self._stamp += float(seconds)

    def clear(self) -> None:
        """Forget the command (e.g. after a reset)."""
        self._cmd = self._zeros
        self._stamp = -math.inf
        self.timed_out = True


class CommandBursts:
    """Bad commands come in bursts (a faulty publisher at its own rate beside the controller):
    one warning at the start of each burst, not one per message, and after a refused command
    (NaN/inf, wrong length) the arm holds until no refused command came for ``hold`` s.

    A burst of one ``kind`` ends when no command of that kind came for ``hold`` s. Times in s.
    """

    def __init__(self, hold: float = 1.0) -> None:
        self.hold = float(hold)
        self._last: dict[str, float] = {}
        self.count: dict[str, int] = {}

    def bad(self, kind: str, now: float) -> bool:
        """Note a bad command of ``kind`` at ``now``; True when it starts a burst (warn now)."""
        last = self._last.get(kind)
        self._last[kind] = now
        start = last is None or now - last >= self.hold
        self.count[kind] = 1 if start else self.count.get(kind, 0) + 1
        return start

    def holding(self, kind: str, now: float) -> bool:
        """True while a burst of ``kind`` lasts (its latest command less than ``hold`` s ago)."""
        last = self._last.get(kind)
        return last is not None and now - last < self.hold

    def clear(self) -> None:
        """Forget every burst (e.g. after a reset)."""
        self._last.clear()
        self.count.clear()


def _read_only(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


__all__ = ['CommandBursts', 'CommandGate', 'gripper_closure', 'validate_velocities']
