"""Grasp outcome detection (ROS-free): an object lifted above the success height in the gripper is a
success; a lifted object that leaves the gripper and falls is a drop. This is the one success
definition of the project: the trial records (mindgrasp_experiments.records) take
``GraspResult.success`` from here.

The node feeds :meth:`TaskMonitor.update` with the simulation after every control tick and
publishes what it returns as ``/task/result`` (mindgrasp_msgs/GraspResult).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mindgrasp_sim.simulation import Simulation

#: object centre height (m) that counts as a successful lift (the original code's 0.22 m)
SUCCESS_HEIGHT = 0.22


@dataclass
class TaskEvent:
    """One grasp outcome. ``lift_height``: highest centre height of the object (m);
    ``duration``: simulated seconds since the trial began (reset)."""

    trial: int
    grasped_object: str
    success: bool
    duration: float
    lift_height: float
    reason: str
    object_id: int = -1


class TaskMonitor:
    """Watches the held object and reports one success or drop per grasp.

    Parameters
    ----------
    success_height : float
        Object centre height (m) above which a held object counts as lifted.
    lift_margin : float
        An object counts as picked up once its centre is this far (m) above its resting height;
        losing it after that is a drop.
    """

    def __init__(self, success_height: float = SUCCESS_HEIGHT, lift_margin: float = 0.02) -> None:
        self.success_height = success_height
        self.lift_margin = lift_margin
        self.trial = 0
        self._reset_state(0.0)

    def _reset_state(self, start: float) -> None:
        self._start = start
        self._tracked: int | None = None     # id of the object being carried
        self._label = ''
        self._rest_z = 0.0
        self._max_z = 0.0
        self._reported = False

    def new_trial(self, sim_time: float = 0.0) -> None:
        """Start a new trial (call after a reset)."""
        self.trial += 1
        self._reset_state(sim_time)

    def update(self, sim: Simulation, robot: str = 'user') -> TaskEvent | None:
        """Check the gripper once; return an event when a success or a drop happened now."""
        held = sim.held_object(robot)
        if held is not None and self._tracked != held.object_id:
            self._tracked, self._label = held.object_id, held.label
            self._rest_z = held.size / 2
            self._max_z = float(held.position[2])
            self._reported = False
        if self._tracked is None:
            return None
        obj = sim.objects()[self._tracked]
        z = float(obj.position[2])
        self._max_z = max(self._max_z, z)
        if held is not None:
            if not self._reported and z > self.success_height:
                self._reported = True
                return TaskEvent(self.trial, self._label, True, sim.time - self._start,
                                 self._max_z, f'lifted above {self.success_height:.2f} m',
                                 self._tracked)
            return None
        # not held any more: a fall before the success height is a drop (one result per grasp:
        # losing the object after a reported success is not reported again)
        event = None
        lifted = self._max_z > self._rest_z + self.lift_margin
        falling = sim.object_velocity(self._tracked)[2] < -0.05
        if lifted and falling and not self._reported:
            event = TaskEvent(self.trial, self._label, False, sim.time - self._start,
                              self._max_z, 'dropped', self._tracked)
        if event is not None or not lifted or (falling and self._reported):
            self._tracked = None
        return event


__all__ = ['SUCCESS_HEIGHT', 'TaskEvent', 'TaskMonitor']
