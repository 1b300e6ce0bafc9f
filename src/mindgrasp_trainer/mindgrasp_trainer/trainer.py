"""The MIndGrasp Trainer (paper, "MIndGrasp Trainer"): a training robot that prompts by moving.

Each trial draws a class, moves the training robot for 2 s in the direction that class means on the
user's robot, then holds it still for 2 s while the user catches up::

    class          training robot motion (joint velocities, rad/s)
    0 left hand    joint 1 (base yaw) +turn_speed       (turns left)
    1 right hand   joint 1 (base yaw) -turn_speed       (turns right)
    2 both hands   joint 2 (shoulder) +approach_speed   (approaches, "long arm" forward)
    3 both feet    joint 2 (shoulder) -approach_speed   (backs away)

Both robots are reset when the training robot's end-effector goes below ``reset_height`` (0.1 m)
or the user's controller enters the grasp state. The task metric is the distance between the two
end-effectors (m). No ROS imports: the node feeds times, poses and controller states in and
publishes what comes out.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from mindgrasp_trainer.protocol import (
    CLASS_NAMES,
    NO_CLASS,
    PromptEvent,
    TrainerError,
    balanced_order,
    check_classes,
)

__all__ = ['TrainerProtocol', 'TrainerStep', 'TrialRecord', 'ee_distance']

#: mindgrasp_msgs/FsmState.GRASP_OBJECT
GRASP_OBJECT = 5


def ee_distance(a: Sequence[float], b: Sequence[float]) -> float:
    """Euclidean distance (m) between two end-effector positions, each shape (3,) in metres."""
    a = np.asarray(a, dtype=float).reshape(-1)
    b = np.asarray(b, dtype=float).reshape(-1)
    if a.shape != (3,) or b.shape != (3,):
        msg = f'End-effector positions need 3 coordinates (x, y, z); got {a.shape} and {b.shape}.'
        raise TrainerError(msg)
    return float(np.linalg.norm(a - b))


@dataclass
class TrialRecord:
    """What happened in one trial; distances in metres, times in seconds from the start."""

    trial: int
    class_index: int
    onset: float
    distances: list[float] = field(default_factory=list)
    final_distance: float = math.nan
    aborted: str = ''

    @property
    def class_name(self) -> str:
        return CLASS_NAMES[self.class_index]

    @property
    def mean_distance(self) -> float:
        return float(np.mean(self.distances)) if self.distances else math.nan


@dataclass
class TrainerStep:
    """Output of :meth:`TrainerProtocol.update`.

    Attributes
    ----------
    command : ndarray, shape (n_joints,)
        Joint velocities for the training robot (rad/s); zeros outside ``move``.
    events : list of PromptEvent
        Prompt phases that started at this update.
    reset : str
        Why both robots must be reset now, '' when they need not.
    done : bool
        The session has ended.
    """

    command: np.ndarray
    events: list[PromptEvent]
    reset: str = ''
    done: bool = False


class TrainerProtocol:
    """State machine of the MIndGrasp Trainer: move 2 s, wait 2 s, reset rule, distance metric.

    Parameters
    ----------
    n_trials : int
        Number of trials; the session ends after the last one.
    classes : sequence of int
        Classes to prompt.
    move_duration, wait_duration : float
        Training robot moving, then holding still (s).
    turn_speed : float
        Joint velocity of ``turn_joint`` for left hand (rad/s); right hand uses ``-turn_speed``.
    approach_speed : float
        Joint velocity of ``approach_joint`` for both hands (rad/s); both feet use the negative.
    turn_joint, approach_joint : int
        Zero-based joint indices (0 = joint 1 base yaw, 1 = joint 2 shoulder).
    n_joints : int
        Length of the velocity command.
    reset_height : float
        Reset when the training end-effector's z (m) falls below this.
    grasp_state : int
        Controller state that triggers a reset when the user's robot enters it.
    settle_time : float
        Rest after a reset before the next trial (s); the height rule is off meanwhile.
    balanced : bool
        Balanced random class order (True) or an independent uniform draw per trial as in the
        paper (False).
    seed : int
        Seed of the class order.
    start_delay : float
        Rest before the first trial (s).
    duration : float
        End the session after this long (s) even if trials remain; 0 means no limit.
    """

    paradigm = 'trainer'

    def __init__(
        self,
        n_trials: int = 40,
        classes: Sequence[int] = (0, 1, 2, 3),
        move_duration: float = 2.0,
        wait_duration: float = 2.0,
        turn_speed: float = 0.2,
        approach_speed: float = 0.05,
        turn_joint: int = 0,
        approach_joint: int = 1,
        n_joints: int = 6,
        reset_height: float = 0.1,
        grasp_state: int = GRASP_OBJECT,
        settle_time: float = 1.0,
        balanced: bool = True,
        seed: int = 0,
        start_delay: float = 0.0,
        duration: float = 0.0,
    ) -> None:
        for name, value in (
            ('move_duration', move_duration),
            ('wait_duration', wait_duration),
            ('settle_time', settle_time),
            ('start_delay', start_delay),
            ('duration', duration),
        ):
            if not math.isfinite(value) or value < 0 or (name == 'move_duration' and value == 0):
                msg = (
                    f"The duration '{name}' must be a finite number of seconds, at least 0 "
                    f'(move_duration above 0); {value} is invalid.'
                )
                raise TrainerError(msg)
        for name, idx in (('turn_joint', turn_joint), ('approach_joint', approach_joint)):
            if not 0 <= idx < n_joints:
                msg = (
                    f"'{name}' is {idx}, outside the {n_joints} joints; "
                    f'use an index from 0 to {n_joints - 1}.'
                )
                raise TrainerError(msg)
        if not (math.isfinite(turn_speed) and math.isfinite(approach_speed)):
            msg = "'turn_speed' and 'approach_speed' must be finite joint velocities (rad/s)."
            raise TrainerError(msg)
        self.classes = check_classes(classes)
        self.n_trials = int(n_trials)
        self.move_duration = float(move_duration)
        self.wait_duration = float(wait_duration)
        self.turn_speed = float(turn_speed)
        self.approach_speed = float(approach_speed)
        self.turn_joint = int(turn_joint)
        self.approach_joint = int(approach_joint)
        self.n_joints = int(n_joints)
        self.reset_height = float(reset_height)
        self.grasp_state = int(grasp_state)
        self.settle_time = float(settle_time)
        self.balanced = bool(balanced)
        self.seed = int(seed)
        self.start_delay = float(start_delay)
        self.duration = float(duration)

        rng = np.random.default_rng(self.seed)
        if self.balanced:
            self.order = balanced_order(self.n_trials, self.classes, rng)
        else:
            if self.n_trials < 1:
                msg = f"The number of trials 'n_trials' must be at least 1; {n_trials} is invalid."
                raise TrainerError(msg)
            self.order = rng.choice(np.asarray(self.classes), size=self.n_trials)

        self.state = 'idle'  # idle | rest | move | wait | resetting | settle | done
        self.t0 = math.nan
        self.trials: list[TrialRecord] = []
        self.resets: list[tuple[float, str]] = []
        self._state_end = math.inf
        self._fsm_state: int | None = None

    # ------------------------------------------------------------------ motion
    def velocity(self, class_index: int) -> np.ndarray:
        """Training robot joint velocities (rad/s), shape (n_joints,), that show ``class_index``."""
        v = np.zeros(self.n_joints)
        if class_index == 0:
            v[self.turn_joint] = self.turn_speed
        elif class_index == 1:
            v[self.turn_joint] = -self.turn_speed
        elif class_index == 2:
            v[self.approach_joint] = self.approach_speed
        elif class_index == 3:
            v[self.approach_joint] = -self.approach_speed
        elif class_index != NO_CLASS:
            msg = f'Class index {class_index} is not a motor-imagery class; use 0 to 3.'
            raise TrainerError(msg)
        return v

    @property
    def trial(self) -> TrialRecord | None:
        """The current (or last) trial, None before the first."""
        return self.trials[-1] if self.trials else None

    @property
    def done(self) -> bool:
        return self.state == 'done'

    # ------------------------------------------------------------------ events
    def _event(self, t: float, phase: str, class_index: int, duration: float) -> PromptEvent:
        trial = self.trial.trial if self.trial is not None else 0
        return PromptEvent(t - self.t0, phase, trial, class_index, duration, self.paradigm)

    def _start_trial(self, t: float) -> PromptEvent:
        k = int(self.order[len(self.trials)])
        self.trials.append(TrialRecord(len(self.trials) + 1, k, t - self.t0))
        self.state = 'move'
        self._state_end = t + self.move_duration
        return self._event(t, 'move', k, self.move_duration)

    def _next_or_end(self, t: float) -> PromptEvent:
        if len(self.trials) >= self.n_trials:
            return self._end(t)
        return self._start_trial(t)

    def _end(self, t: float) -> PromptEvent:
        self.state = 'done'
        self._state_end = math.inf
        return self._event(t, 'end', NO_CLASS, 0.0)

    def start(self, t: float) -> list[PromptEvent]:
        """Begin the session at time ``t`` (s, any monotonic clock); return the first events."""
        if self.state != 'idle':
            msg = 'This trainer session has already started; make a new TrainerProtocol to rerun.'
            raise TrainerError(msg)
        self.t0 = float(t)
        if self.start_delay > 0:
            self.state = 'rest'
            self._state_end = t + self.start_delay
            return [self._event(t, 'rest', NO_CLASS, self.start_delay)]
        return [self._start_trial(t)]

    # ------------------------------------------------------------------ loop
    def update(
        self,
        t: float,
        trainer_ee_z: float | None = None,
        fsm_state: int | None = None,
    ) -> TrainerStep:
        """Advance to time ``t`` (s) with the latest inputs.

        Parameters
        ----------
        t : float
            Current time (s), same clock as :meth:`start`.
        trainer_ee_z : float or None
            Height of the training robot's end-effector (m), None when not known yet.
        fsm_state : int or None
            The user's controller state (mindgrasp_msgs/FsmState.state), None when not known.

        Returns
        -------
        TrainerStep
        """
        if self.state == 'idle':
            msg = 'TrainerProtocol.update() was called before start(); call start(t) first.'
            raise TrainerError(msg)
        events: list[PromptEvent] = []
        reset = ''
        entered_grasp = (
            fsm_state is not None
            and int(fsm_state) == self.grasp_state
            and self._fsm_state is not None
            and self._fsm_state != self.grasp_state
        )
        if fsm_state is not None:
            self._fsm_state = int(fsm_state)

        if self.state != 'done' and self.duration > 0 and t - self.t0 >= self.duration:
            if self.trial is not None and self.state in ('move', 'wait'):
                self.trial.aborted = 'duration'
            events.append(self._end(t))
        elif self.state in ('move', 'wait'):
            if trainer_ee_z is not None and trainer_ee_z < self.reset_height:
                reset = (
                    f'training end-effector at {trainer_ee_z:.4f} m, '
                    f'below {self.reset_height:.3f} m'
                )
            elif entered_grasp:
                reset = "user's robot entered the grasp state"
            if reset:
                self.trial.aborted = reset
                self.resets.append((t - self.t0, reset))
                self.state = 'resetting'
                self._state_end = math.inf
                events.append(self._event(t, 'rest', NO_CLASS, self.settle_time))
        # time-driven transitions; a loop so that a late update does not skip a phase's event
        while t >= self._state_end:
            t_switch = self._state_end
            if self.state == 'move':
                self.state = 'wait'
                self._state_end = t_switch + self.wait_duration
                k = self.trial.class_index
                events.append(self._event(t_switch, 'wait', k, self.wait_duration))
            elif self.state in ('wait', 'rest', 'settle'):
                events.append(self._next_or_end(t_switch))
            else:  # pragma: no cover - states without a deadline
                break
        moving = self.state == 'move'
        command = self.velocity(self.trial.class_index) if moving else np.zeros(self.n_joints)
        return TrainerStep(command, events, reset, self.state == 'done')

    def reset_finished(self, t: float, success: bool = True) -> None:
        """Tell the protocol the reset asked for has completed (or failed) at time ``t`` (s).

        The next trial starts ``settle_time`` later. After a failed reset the session goes on too:
        the caller logs why, and the height rule fires again if the robot is still too low.
        """
        if self.state != 'resetting':
            return
        self.state = 'settle'
        self._state_end = t + self.settle_time

    def record_distance(self, d: float) -> None:
        """Log an end-effector distance sample (m) for the current trial (move or wait phase)."""
        if self.trial is None or not math.isfinite(d) or self.state not in ('move', 'wait'):
            return
        self.trial.distances.append(float(d))
        self.trial.final_distance = float(d)

    def summary(self) -> dict:
        """Session figures: trials, resets, mean end-effector distance overall and per class (m)."""
        per_class = {}
        for k in self.classes:
            ds = [d for tr in self.trials if tr.class_index == k for d in tr.distances]
            per_class[CLASS_NAMES[k]] = float(np.mean(ds)) if ds else math.nan
        all_d = [d for tr in self.trials for d in tr.distances]
        return {
            'n_trials': len(self.trials),
            'n_aborted': sum(1 for tr in self.trials if tr.aborted),
            'n_resets': len(self.resets),
            'mean_ee_distance': float(np.mean(all_d)) if all_d else math.nan,
            'mean_final_ee_distance': float(
                np.nanmean([tr.final_distance for tr in self.trials])
            )
            if any(math.isfinite(tr.final_distance) for tr in self.trials)
            else math.nan,
            'per_class_ee_distance': per_class,
        }
