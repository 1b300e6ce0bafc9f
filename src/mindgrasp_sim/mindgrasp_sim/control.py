"""Command handling shared by the node and tests (ROS-free): validation of joint velocity and
gripper commands, the command timeout of a forward velocity controller, and the joint velocities
the two other arm interfaces stand for (a streamed JointTrajectoryController trajectory, a MoveIt
Servo twist), so that every interface goes through the same gate, limits and warnings."""

from __future__ import annotations

import math

import numpy as np

from mindgrasp_common.redundancy import redundancy_step
from mindgrasp_sim.errors import SimError


def validate_velocities(values: object, n_joints: int = 6) -> np.ndarray:
    """A velocity command as a float array (n_joints,) rad/s; SimError naming the problem for a
    wrong length or NaN/inf."""
    v = np.asarray(values, dtype=float).reshape(-1)
    if v.size != n_joints:
        msg = (f'Joint velocity command has {v.size} values but the arm has {n_joints} joints; '
               f'send {n_joints} velocities in rad/s, one per arm joint in the order of '
               '/joint_states.')
        raise SimError(msg)
    if not np.isfinite(v).all():
        msg = f'Joint velocity command contains NaN or inf ({v.tolist()}); send finite ' \
              'velocities in rad/s.'
        raise SimError(msg)
    return v


def velocities_from_trajectory(joint_names: list[str], arm_joints: list[str] | tuple[str, ...],
                               positions: np.ndarray, velocities: np.ndarray,
                               time_from_start: float, q: np.ndarray) -> np.ndarray:
    """Joint velocities (n,) rad/s, in ``arm_joints`` order, that follow the first point of a
    streamed trajectory: its velocities when it has them, else the way from the joints ``q``
    (n,) rad to its positions in ``time_from_start`` s. SimError naming the problem for joint
    names other than the arm's, sizes that do not match them, NaN/inf or a point at time 0
    without velocities."""
    names = list(joint_names)
    if sorted(names) != sorted(arm_joints):
        msg = (f'JointTrajectory joint_names {names} are not the arm joints; send '
               f'joint_names {list(arm_joints)} (any order).')
        raise SimError(msg)
    order = [names.index(n) for n in arm_joints]
    velocities = np.asarray(velocities, dtype=float).reshape(-1)
    positions = np.asarray(positions, dtype=float).reshape(-1)
    if velocities.size:
        if velocities.size != len(names):
            msg = (f'JointTrajectory point has {velocities.size} velocities for {len(names)} '
                   'joint_names; send one per joint (rad/s) or none.')
            raise SimError(msg)
        return validate_velocities(velocities[order], len(names))
    if positions.size != len(names):
        msg = (f'JointTrajectory point has {positions.size} positions for {len(names)} '
               'joint_names; send one per joint (rad).')
        raise SimError(msg)
    if not (math.isfinite(time_from_start) and time_from_start > 0):
        msg = (f'JointTrajectory point without velocities has time_from_start '
               f'{time_from_start} s; give it a time > 0 s or velocities.')
        raise SimError(msg)
    return validate_velocities((positions[order] - np.asarray(q, dtype=float)) / time_from_start,
                               len(names))


def velocities_from_twist(jacobian: np.ndarray, linear: np.ndarray, angular: np.ndarray,
                          damping: float = 0.01,
                          posture: tuple[np.ndarray, ...] | None = None) -> np.ndarray:
    """Joint velocities (n,) rad/s that move the tool at ``linear`` (3,) m/s and ``angular``
    (3,) rad/s, by damped least squares on the tool ``jacobian`` (6, n), as MoveIt Servo does
    with its inverse Jacobian (the damping keeps a near-singular arm from racing). SimError for
    NaN/inf.

    ``posture``: ``(q, home, lower, upper)`` (n,) rad each; a seven-joint arm moving at a
    non-zero twist spends its null-space motion on going back towards ``home`` and away from
    its limits (:func:`~mindgrasp_common.redundancy.redundancy_step`); a zero twist stops the arm
    (it never moves by itself). Ignored for six joints."""
    twist = np.concatenate([np.asarray(linear, dtype=float), np.asarray(angular, dtype=float)])
    if not np.isfinite(twist).all():
        msg = f'Twist contains NaN or inf ({twist.tolist()}); send finite m/s and rad/s.'
        raise SimError(msg)
    j = np.asarray(jacobian, dtype=float)
    v = j.T @ np.linalg.solve(j @ j.T + damping ** 2 * np.eye(6), twist)
    if posture is not None and j.shape[1] > 6 and twist.any():
        v = v + redundancy_step(j, *posture)
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


__all__ = ['CommandBursts', 'CommandGate', 'gripper_closure', 'validate_velocities',
           'velocities_from_trajectory', 'velocities_from_twist']
