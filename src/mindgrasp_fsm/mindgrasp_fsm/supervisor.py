"""The controller's safety supervisor: whether anything may move at a tick (ROS-free; used by
:class:`~mindgrasp_fsm.grasp_fsm.GraspFsm`).

Every tick it judges the inputs (joint states, MI predictions, camera images) by their age, waits
for inputs that have not streamed yet (a start-up is no fault), latches a sensor fault (joint
states stale, with NaN/inf, or refused by the node) until they were clean for
``sensor_clean_time``, and after a prediction loss or a released fault holds until the person's
fresh decision (``resume_after_stale``). The controller's module docstring gives the rules.
"""

from __future__ import annotations

import numpy as np

from mindgrasp_common.mi import REST
from mindgrasp_fsm.answer import CLASS_WORDS
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import FsmInputs, StopKind

__all__ = ['INPUT_STREAMS', 'SENSOR_FAULT', 'SafetySupervisor']

#: how the events of a sensor-fault latch begin (the node logs them as warnings)
SENSOR_FAULT = 'sensor fault'
#: the inputs whose age the watchdog judges (names in its messages)
INPUT_STREAMS = ('joint states', 'MI predictions', 'camera images')


class SafetySupervisor:
    """Why the arm must hold at a tick, if it must, and of what kind the stop is.

    Parameters
    ----------
    params : FsmParams
        The controller's parameters, read at every tick (live changes apply at once):
        ``watchdog_timeout``, ``camera_timeout``, ``sensor_clean_time``, ``resume_after_stale``,
        ``resume_hold``, ``autonomous``.
    n_joints : int
        Arm joints: joint states with another number of positions are a fault.
    """

    def __init__(self, params: FsmParams, n_joints: int) -> None:
        self.params = params
        self.n_joints = n_joints
        self._events: list[str] = []
        # after a prediction loss: the stamp of the first fresh prediction (None: no loss
        # pending), and the class held since which stamp
        self._stale_pred = False
        self._back_at: float | None = None
        self._fresh: tuple[int, float] | None = None
        self._loss = 'prediction loss'
        # start-up: an input "streams" once it was fresh for sensor_clean_time without a break,
        # or once the arm moved; before that an old message is a sender still starting up (the
        # nodes come up in any order, a loaded machine delays the first messages): the arm
        # waits for it, no fault latches (name -> fresh since, s)
        self._fresh_since: dict[str, float] = {}
        self._streaming: set[str] = set()
        # sensor-fault latch: time (s) of the latest joint-state fault seen (None: not latched)
        self._fault_at: float | None = None
        self._fault_why = ''

    def check(self, inputs: FsmInputs, now: float) -> tuple[StopKind, str]:
        """The stop at ``now`` (s) and why, ``(StopKind.NONE, '')`` when the arm may move."""
        kind, why = self._watchdog(inputs, now)
        if not why:
            kind, why = StopKind.FAULT, self._await_fresh_decision(inputs)
        return (kind, why) if why else (StopKind.NONE, '')

    @property
    def fault(self) -> str:
        """What the latched sensor fault is about ('' while none is latched)."""
        return self._fault_why if self._fault_at is not None else ''

    def arm_moved(self) -> None:
        """The arm moved: from now on an old input is a fault (latched), never a late start."""
        self._streaming.update(INPUT_STREAMS)

    def take_events(self) -> list[str]:
        """The events since the last call (fault latched / released, fresh decision)."""
        events, self._events = self._events, []
        return events

    def _watchdog(self, inputs: FsmInputs, now: float) -> tuple[StopKind, str]:
        """Why nothing may move at ``now`` (s), and what kind of stop that is; '' when all
        inputs are fresh."""
        p = self.params
        if inputs.joints is None:
            return StopKind.AWAITING_INPUT, 'stopped: no joint states received yet'
        age = now - inputs.joints.stamp
        refused = inputs.joint_fault is not None and \
            now - inputs.joint_fault[0] < p.sensor_clean_time
        if self._starting_up('joint states', age, p.watchdog_timeout, now) and \
                self._fault_at is None and not refused:
            return StopKind.AWAITING_INPUT, (f'stopped: waiting for the joint states to stream '
                                             f'(the latest is {age:.2f} s old, limit '
                                             f'{p.watchdog_timeout:.2f} s)')
        why = self._sensor_latch(inputs, now)
        if why:
            return StopKind.FAULT, why
        if not p.autonomous:
            pred = inputs.prediction
            if pred is None:
                return StopKind.AWAITING_INPUT, 'stopped: no MI prediction received yet'
            age = now - pred.stamp
            if self._starting_up('MI predictions', age, p.watchdog_timeout, now):
                return StopKind.AWAITING_INPUT, (f'stopped: waiting for the MI predictions to '
                                                 f'stream (the latest is {age:.2f} s old, limit '
                                                 f'{p.watchdog_timeout:.2f} s)')
            if age > p.watchdog_timeout:
                self._stale_pred = True
                self._back_at = self._fresh = None
                self._loss = 'prediction loss'
                return StopKind.FAULT, (
                    f'stopped: the latest MI prediction is {age:.2f} s old (limit '
                    f'{p.watchdog_timeout:.2f} s); check the classifier and EEG stream')
        if inputs.vision is None:
            return (StopKind.AWAITING_INPUT,
                    'stopped: no camera images received yet; holding still')
        age = now - inputs.vision.stamp
        if self._starting_up('camera images', age, p.camera_timeout, now):
            return StopKind.AWAITING_INPUT, (f'stopped: waiting for the camera images to stream '
                                             f'(the latest is {age:.2f} s old, limit '
                                             f'{p.camera_timeout:.2f} s); holding still')
        if age > p.camera_timeout:
            return StopKind.FAULT, (f'stopped: no camera images for {age:.2f} s (limit '
                                    f'{p.camera_timeout:.2f} s); holding still')
        return StopKind.NONE, ''

    def _starting_up(self, name: str, age: float, limit: float, now: float) -> bool:
        """True while input ``name``, whose latest message is ``age`` s old at ``now`` (s), is
        older than ``limit`` s but has not streamed yet: its sender is still starting up, and the
        arm (which has not moved) waits for it instead of latching a fault.

        An input streams once it was no older than ``limit`` for ``sensor_clean_time`` s
        without a break, or once the arm moved; after that an old message is a fault."""
        if name in self._streaming:
            return False
        if age > limit:
            self._fresh_since.pop(name, None)
            return True
        since = self._fresh_since.setdefault(name, now)
        if now - since >= self.params.sensor_clean_time:
            self._streaming.add(name)
        return False

    def _joint_fault(self, inputs: FsmInputs, now: float) -> str:
        """What is wrong with the joint states at ``now`` (s), '' when nothing."""
        p = self.params
        joints = inputs.joints
        assert joints is not None
        age = now - joints.stamp
        if age > p.watchdog_timeout:
            return (f'joint states are {age:.2f} s old (limit {p.watchdog_timeout:.2f} s); '
                    'check the arm driver')
        pos = np.asarray(joints.position, dtype=float)
        if pos.shape != (self.n_joints,):
            return f'joint states hold {pos.size} positions, {self.n_joints} expected'
        if not np.isfinite(pos).all() or not np.isfinite(np.asarray(joints.velocity)).all():
            return 'joint states contain NaN or infinite values; check the arm driver'
        return ''

    def _sensor_latch(self, inputs: FsmInputs, now: float) -> str:
        """'' when the joint states may be used, else why the arm holds (a latched stop).

        A fault now, or a faulty message received since the last one seen, (re)starts the
        latch; it is released once nothing was wrong for ``sensor_clean_time`` s, and the arm
        then waits for a fresh decision, by the mechanism of a prediction loss.
        """
        p = self.params
        why = self._joint_fault(inputs, now)
        fault_at = now if why else None
        received = inputs.joint_fault
        if received is not None and (self._fault_at is None or received[0] > self._fault_at) \
                and now - received[0] < p.sensor_clean_time:
            fault_at, why = (fault_at or received[0]), why or received[1]
        if fault_at is not None:
            if self._fault_at is None:
                self._events.append(f'{SENSOR_FAULT}: {why}; the arm holds until the joint states'
                                    f' are clean for {p.sensor_clean_time:.1f} s and a new '
                                    'command is given')
            self._fault_at, self._fault_why = fault_at, why
        if self._fault_at is None:
            return ''
        clean = now - self._fault_at
        if clean < p.sensor_clean_time:
            return (f'stopped: {SENSOR_FAULT} ({self._fault_why}); clean for {clean:.2f} of '
                    f'{p.sensor_clean_time:.2f} s, then a new command restarts the arm')
        self._fault_at = None
        self._events.append(f'{SENSOR_FAULT} released: joint states clean for {clean:.2f} s'
                            + ('' if p.autonomous else '; waiting for a new command'))
        # the person restarts the arm as after a prediction loss, with decisions stamped after
        # the release only
        self._stale_pred = True
        self._back_at, self._fresh = now, None
        self._loss = SENSOR_FAULT
        return ''

    def _await_fresh_decision(self, inputs: FsmInputs) -> str:
        """'' once the controller may move after a prediction loss, else why it holds still.

        A fresh decision: every prediction stamped from the first fresh one after the loss on
        decodes the same class for ``resume_hold`` s. A prediction of another class starts the
        count again.
        """
        p = self.params
        if not self._stale_pred or p.autonomous:
            return ''
        if p.resume_after_stale == 'resume':
            self._stale_pred = False
            return ''
        pred = inputs.prediction
        assert pred is not None            # the watchdog passed: fresh predictions arrive
        if self._back_at is None:
            self._back_at = pred.stamp
        if pred.class_index == REST:
            self._fresh = None           # rest is no command: it cannot restart the arm
        elif pred.stamp >= self._back_at and (self._fresh is None or
                                              self._fresh[0] != pred.class_index):
            self._fresh = (pred.class_index, pred.stamp)
        held = pred.stamp - self._fresh[1] if self._fresh is not None else 0.0
        if held >= p.resume_hold:
            self._stale_pred = False
            self._back_at = self._fresh = None
            self._events.append(f'fresh decision after the {self._loss}: '
                                f'{CLASS_WORDS.get(pred.class_index, pred.class_index)}')
            return ''
        back = ('the joint states are clean again after a fault' if self._loss == SENSOR_FAULT
                else 'the MI predictions are back after a loss')
        return (f'stopped: {back}; waiting for a new command '
                f'(one class for {p.resume_hold:.1f} s, resume_after_stale)')

