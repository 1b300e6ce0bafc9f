"""The arm command a driver takes, from the controller's joint velocities (ROS-free).

The controller computes joint velocities (rad/s), already acceleration-limited
(:mod:`mindgrasp_fsm.acceleration`) and zero when its inputs are stale; this module only changes
their form for the driver, so every safety rule holds for every interface:

============  ======================================================  ==============================
interface     what a driver gets                                      as taken by
============  ======================================================  ==============================
velocity      the velocities (6,) rad/s                               ros2_control forward velocity
                                                                      controller
trajectory    a short trajectory from the current joints: points at    ros2_control
              ``k * horizon / n_points`` (k = 1..n_points) with       JointTrajectoryController
              positions ``q + v t`` and velocities ``v``              (streamed, header stamp 0 =
                                                                      start now)
servo_twist   the tool's Cartesian twist ``J(q) v``: linear (3,) m/s,  MoveIt Servo (TWIST command
              angular (3,) rad/s in the arm's base frame               type)
============  ======================================================  ==============================

A zero velocity becomes a trajectory that holds the current joints at rest, or a zero twist.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from mindgrasp_fsm.errors import FsmError

#: the values of the controller's ``command_interface`` parameter
COMMAND_INTERFACES = ('velocity', 'trajectory', 'servo_twist')


class HasJacobian(Protocol):
    """A robot model with the tool's geometric Jacobian (e.g. :class:`UrdfKinematics`)."""

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Jacobian (6, n_joints) [linear m/s; angular rad/s] per rad/s at joints ``q`` (rad)."""
        ...


def check_command_interface(name: str) -> str:
    """``name`` when it is one of :data:`COMMAND_INTERFACES`; FsmError naming the fix otherwise."""
    if name not in COMMAND_INTERFACES:
        msg = (f"command_interface is {name!r}; use one of {', '.join(COMMAND_INTERFACES)} "
               '(e.g. command_interface:=trajectory).')
        raise FsmError(msg)
    return name


@dataclass(frozen=True)
class TrajectoryCommand:
    """A streamed joint trajectory: ``times`` (n_points,) s after its start, ``positions`` and
    ``velocities`` (n_points, n_joints) rad and rad/s."""

    times: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray


def trajectory_command(q: np.ndarray, v: np.ndarray, horizon: float = 0.1,
                       n_points: int = 2) -> TrajectoryCommand:
    """The trajectory that moves from joints ``q`` (n,) rad at velocities ``v`` (n,) rad/s for
    ``horizon`` s, as ``n_points`` evenly spaced points (the first one ``horizon / n_points``
    ahead: a JointTrajectoryController starts from where the arm is)."""
    q = np.asarray(q, dtype=float)
    v = np.asarray(v, dtype=float)
    times = horizon * np.arange(1, n_points + 1) / n_points
    return TrajectoryCommand(times, q[None, :] + times[:, None] * v[None, :],
                             np.repeat(v[None, :], n_points, axis=0))


def twist_command(kinematics: HasJacobian, q: np.ndarray, v: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The tool twist for joint velocities ``v`` (n,) rad/s at joints ``q`` (n,) rad:
    ``(linear (3,) m/s, angular (3,) rad/s)`` in the base frame."""
    twist = kinematics.jacobian(np.asarray(q, dtype=float)) @ np.asarray(v, dtype=float)
    return twist[:3], twist[3:]


__all__ = ['COMMAND_INTERFACES', 'HasJacobian', 'TrajectoryCommand', 'check_command_interface',
           'trajectory_command', 'twist_command']
