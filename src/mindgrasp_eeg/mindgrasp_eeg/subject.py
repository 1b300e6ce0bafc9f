"""The virtual subject: decides which motor-imagery class is imagined at each moment.

Modes (all seeded: same seed and same inputs, same decisions):

``noise``
    Never imagines anything, like the paper's unworn cap: the EEG carries no class information.
``follow``
    Imagines the class of each trainer prompt (``/trainer/prompt``) during the active phases
    (default ``cue``, ``move``, ``wait``: Graz cue + imagery, Trainer move + wait), starting
    ``reaction_delay`` seconds after the prompt. Per prompted trial it lapses (imagines nothing)
    with probability ``lapse_rate``; otherwise it imagines the prompted class with probability
    ``accuracy`` and one of the three other classes (uniformly) otherwise.
``pursue``
    Acts as a competent user of the MIndGrasp controller, instructed in its paradigm (see
    :func:`pursue_class` for ``paper`` and :func:`scan_class` for ``scan``), from the task
    target, the scene objects, the base joint angle and the controller state. Every
    ``decision_period`` seconds it re-decides; the decision is right with probability ``accuracy``.
    A new target cancels what was still to come for the old one: the subject rests and decides
    afresh for the new target (it aims first: both hands only once the arm faces the target).

Times are seconds on any monotonic clock the caller chooses (ROS time in the node).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence

import numpy as np

from mindgrasp_common.arm_heading import ArmHeading
from mindgrasp_common.geometry import wrap_angle
from mindgrasp_common.states import State
from mindgrasp_common.types import SceneObject

from . import EEGError
from .montage import BOTH_FEET, BOTH_HANDS, LEFT_HAND, NO_CLASS, RIGHT_HAND

MODES = ('noise', 'follow', 'pursue')



def find_target(objects: Sequence[SceneObject], object_id: int = -1, colour: str = '',
                shape: str = '') -> SceneObject | None:
    """The target object: by id when ``object_id >= 0`` and present, else by colour and shape."""
    if object_id >= 0:
        for obj in objects:
            if obj.object_id == object_id:
                return obj
    for obj in objects:
        if obj.colour == colour and obj.shape == shape and colour:
            return obj
    return None


def same_object(seen: str, wanted: str) -> bool:
    """Whether the controller's object of interest ``seen`` ("<colour> <shape>", shape
    ``unknown`` until the shape CNN has named it) can be the ``wanted`` object."""
    colour, _, shape = seen.partition(' ')
    w_colour, _, w_shape = wanted.partition(' ')
    return colour == w_colour and shape in (w_shape, 'unknown', '')


def subject_heading(robot: str, joint: str = '') -> ArmHeading:
    """How a subject node reads the arm's heading from ``/joint_states``: from the robot's model
    (``robot``, a :func:`~mindgrasp_common.robot_description.load_robot` spec) when given,
    else the angle of ``joint`` ('' = the first joint listed) as it is. A ``joint`` given
    names the joint read either way."""
    if not robot:
        return ArmHeading(joint)
    heading = ArmHeading.of_robot(robot)
    return dataclasses.replace(heading, joint=joint) if joint else heading


def pursue_class(target: SceneObject | None, base_yaw: float, fsm_state: int,
                 object_of_interest: str = '', *, heading_tolerance: float = 0.1,
                 stopped: bool = False) -> int | None:
    """What a competent user imagines to reach ``target`` (pure function).

    Parameters
    ----------
    target : SceneObject or None
        The desired object in the base frame; None (unknown target) -> rest.
    base_yaw : float
        Heading of the arm (rad): the base joint angle plus the arm's heading at zero; positive
        is to the left (counter-clockwise seen from above), as the controller turns left with
        positive joint-1 velocity.
    fsm_state : int
        ``FsmState.state`` (1 search, 2 centre, 3 initial approach, 4 final approach, 5 grasp,
        6 return); 0 = unknown, treated as search.
    object_of_interest : str
        ``"<colour> <shape>"`` the controller is working on, empty when none.
    heading_tolerance : float
        Heading error (rad) under which the user considers the target centred.
    stopped : bool
        ``FsmState.stopped``: the controller holds the arm still. After a prediction loss it
        waits for a fresh command (one class held, ``resume_after_stale``), so a user who would
        rest in an autonomous state imagines both hands ("go on") until the arm moves again.

    Returns
    -------
    int or None
        0 left hand (turn left), 1 right hand (turn right), 2 both hands (stop the search /
        approach), 3 both feet (back away from a wrong object), None (rest: the controller is
        autonomous or there is nothing to do).
    """
    if target is None:
        return None
    go_on = BOTH_HANDS if stopped else None  # both hands: what the autonomous states ignore
    if fsm_state in (State.FINAL_APPROACH, State.GRASP_OBJECT, State.RETURN_TO_START):
        return go_on
    wrong = bool(object_of_interest) and not same_object(object_of_interest, target.label)
    if fsm_state == State.CENTER_OBJECT:
        return BOTH_FEET if wrong else go_on
    if fsm_state == State.INITIAL_APPROACH:
        # the controller keeps the object centred itself: push on to it, or back off a wrong one
        return BOTH_FEET if wrong else BOTH_HANDS
    error = wrap_angle(math.atan2(target.y, target.x) - base_yaw)
    if error > heading_tolerance:
        return LEFT_HAND
    if error < -heading_tolerance:
        return RIGHT_HAND
    return BOTH_HANDS


def scan_class(target: SceneObject | None, base_yaw: float, fsm_state: int, *,
               offered: bool = False, heading_tolerance: float = 0.3,
               stopped: bool = False, yes: int | None = BOTH_HANDS,
               no: int | None = BOTH_FEET) -> int | None:
    """What a person instructed in the ``scan`` paradigm imagines (pure function).

    The arm turns from object to object by itself and offers each one it has centred
    (``FsmState.offered``); the person looks where the arm points. Instructions: while the arm
    offers an object, imagine both hands for the one you want and both feet for any other;
    while it approaches the one you want keep imagining both hands, and both feet if it
    approaches another; rest while it searches.

    Parameters
    ----------
    target : SceneObject or None
        The desired object in the base frame; None -> rest.
    base_yaw : float
        Heading of the arm (rad), as for :func:`pursue_class`.
    fsm_state : int
        ``FsmState.state``.
    offered : bool
        ``FsmState.offered``: the controller waits for a confirmation of the object it faces.
    heading_tolerance : float
        Heading error (rad) under which the person sees the arm pointing at the target (set
        locations are 0.7 rad apart).
    stopped : bool
        ``FsmState.stopped``: after a prediction loss the controller waits for a fresh command;
        the person imagines the "yes" class ("go on") until it moves again.
    yes, no : int or None
        The person's answer pair (:mod:`mindgrasp_common.answer_pair`, ``FsmState.yes_classes``
        / ``no_classes``): the class imagined for yes and for no (None: rest). Default both
        hands / both feet.

    Returns
    -------
    int or None
        ``yes`` (yes / go on), ``no`` (no / cancel), None (rest).
    """
    if target is None:
        return None
    if stopped:
        return BOTH_HANDS if yes is None else yes
    facing = abs(wrap_angle(math.atan2(target.y, target.x) - base_yaw)) <= heading_tolerance
    if (fsm_state in (State.OBJECT_SEARCH, State.CENTER_OBJECT) and offered) or \
            fsm_state in (State.INITIAL_APPROACH, State.FINAL_APPROACH):
        return yes if facing else no
    return None


class VirtualSubject:
    """Seeded virtual BCI user (see module docstring for the modes).

    Parameters
    ----------
    mode : {'noise', 'follow', 'pursue'}
    accuracy : float
        Probability (0..1) that a (non-lapsed) decision is the right class.
    reaction_delay : float
        Seconds from a prompt (or a pursue decision) to the start of imagery.
    lapse_rate : float
        Probability (0..1) that a prompted trial is not imagined at all (follow mode).
    seed : int
    active_phases : sequence of str
        Prompt phases during which the prompted class is imagined (follow mode).
    decision_period : float
        Seconds between decisions in pursue mode.
    heading_tolerance : float
        See :func:`pursue_class` (rad).
    """

    def __init__(self, mode: str = 'noise', *, accuracy: float = 1.0, reaction_delay: float = 0.5,
                 lapse_rate: float = 0.0, seed: int = 0,
                 active_phases: Sequence[str] = ('cue', 'move', 'wait'),
                 decision_period: float = 0.5,
                 heading_tolerance: float = 0.1) -> None:
        if mode not in MODES:
            msg = f'The virtual subject mode must be one of {MODES}; {mode!r} is unknown.'
            raise EEGError(msg)
        for name, value in (('accuracy', accuracy), ('lapse_rate', lapse_rate)):
            if not 0.0 <= value <= 1.0:
                msg = f'The virtual subject {name} must be within 0..1; {value} is invalid.'
                raise EEGError(msg)
        if reaction_delay < 0 or decision_period <= 0:
            msg = (f'reaction_delay must be >= 0 s and decision_period > 0 s; got '
                   f'{reaction_delay} s and {decision_period} s.')
            raise EEGError(msg)
        self.mode, self.accuracy, self.reaction_delay = mode, accuracy, reaction_delay
        self.lapse_rate, self.active_phases = lapse_rate, tuple(active_phases)
        self.decision_period, self.heading_tolerance = decision_period, heading_tolerance
        self._rng = np.random.default_rng(seed)
        self._schedule: list[tuple[float, int | None]] = []   # (effective time, class), sorted
        self._current: int | None = None
        self._trial_key: tuple[int, int] | None = None
        self._trial_choice: int | None = None
        self._next_decision = -math.inf
        self._last_t = -math.inf
        # pursue inputs
        self.objects: list[SceneObject] = []
        self.target_id, self.target_colour, self.target_shape = -1, '', ''
        self._target_changed = False
        self.base_yaw, self.fsm_state, self.object_of_interest = 0.0, 0, ''
        self.fsm_stopped = False
        self.paradigm, self.offered = 'paper', False
        self.yes_class: int | None = BOTH_HANDS     # scan: the answer pair in force
        self.no_class: int | None = BOTH_FEET
        #: (time, asked class or None, imagined class or None) for every decision taken
        self.decisions: list[tuple[float, int | None, int | None]] = []

    # -- follow --------------------------------------------------------------------------------
    def on_prompt(self, t: float, class_index: int, phase: str, trial: int = 0) -> None:
        """A trainer prompt arrived at time ``t`` (s); only used in follow mode."""
        if self.mode != 'follow':
            return
        asked = None if class_index == NO_CLASS or class_index > BOTH_FEET else int(class_index)
        if asked is None or phase not in self.active_phases:
            self._schedule_at(t + self.reaction_delay, None)
            return
        key = (trial, asked)
        if key != self._trial_key:        # one decision per prompted trial (cue then move = same)
            self._trial_key = key
            self._trial_choice = self._choose(asked, lapse=True)
            self.decisions.append((t, asked, self._trial_choice))
        self._schedule_at(t + self.reaction_delay, self._trial_choice)

    # -- pursue --------------------------------------------------------------------------------
    def set_target(self, object_id: int, colour: str, shape: str) -> None:
        """The desired object (``/task/target``); a new one cancels pending decisions."""
        new = (object_id, colour, shape)
        if new != (self.target_id, self.target_colour, self.target_shape):
            self._target_changed = True
        self.target_id, self.target_colour, self.target_shape = new

    def set_objects(self, objects: Sequence[SceneObject]) -> None:
        """Scene objects in the base frame (``/sim/objects``)."""
        self.objects = list(objects)

    def set_base_yaw(self, yaw: float) -> None:
        """Arm heading (rad), from ``/joint_states``."""
        self.base_yaw = float(yaw)

    def set_fsm(self, state: int, object_of_interest: str = '', stopped: bool = False,
                paradigm: str = '', offered: bool = False, yes_classes: Sequence[int] = (),
                no_classes: Sequence[int] = ()) -> None:
        """Controller state (``/fsm/state``): its number, object of interest, stop flag, the
        paradigm it runs (``''``: a controller that does not say is taken as ``paper``),
        whether it offers its object of interest (scan) and its answer pair (scan: the first
        yes and no class is what the subject imagines, rest (4) is no imagery; empty: a
        controller that does not say leaves it: both hands / both feet until one does)."""
        self.fsm_state, self.object_of_interest = int(state), object_of_interest
        self.fsm_stopped = bool(stopped)
        self.paradigm, self.offered = paradigm or 'paper', bool(offered)
        if len(yes_classes) and len(no_classes):
            self.yes_class = None if int(yes_classes[0]) > BOTH_FEET else int(yes_classes[0])
            self.no_class = None if int(no_classes[0]) > BOTH_FEET else int(no_classes[0])

    def competent_class(self) -> int | None:
        """What a competent user would imagine now (pursue mode inputs, no errors)."""
        target = find_target(self.objects, self.target_id, self.target_colour, self.target_shape)
        if self.paradigm == 'scan':
            return scan_class(target, self.base_yaw, self.fsm_state, offered=self.offered,
                              stopped=self.fsm_stopped, yes=self.yes_class, no=self.no_class)
        return pursue_class(target, self.base_yaw, self.fsm_state, self.object_of_interest,
                            heading_tolerance=self.heading_tolerance, stopped=self.fsm_stopped)

    # -- output --------------------------------------------------------------------------------
    def intent(self, t: float) -> int | None:
        """Class imagined at time ``t`` (s), None for rest.

        Call with non-decreasing ``t``; if time goes backwards (a simulation reset), pending
        decisions are dropped and the subject decides afresh.
        """
        if t < self._last_t:
            self._next_decision = -math.inf
            self._schedule = [(min(te, t), c) for te, c in self._schedule[-1:]]
        self._last_t = t
        if self.mode == 'pursue' and self._target_changed:
            # imagery meant for the old target (e.g. both hands to select it) must not select
            # whatever is in front now: stop, and decide for the new target from here
            self._target_changed = False
            self._schedule = []
            self._current = None
            self._next_decision = t
        if self.mode == 'pursue' and t >= self._next_decision:
            self._next_decision = t + self.decision_period
            right = self.competent_class()
            chosen = self._choose(right, lapse=False)
            self.decisions.append((t, right, chosen))
            self._schedule_at(t + self.reaction_delay, chosen)
        while self._schedule and self._schedule[0][0] <= t:
            self._current = self._schedule.pop(0)[1]
        return self._current

    def _choose(self, right: int | None, *, lapse: bool) -> int | None:
        if lapse and self._rng.random() < self.lapse_rate:
            return None
        if self._rng.random() < self.accuracy:
            return right
        others = [c for c in (LEFT_HAND, RIGHT_HAND, BOTH_HANDS, BOTH_FEET) if c != right]
        return int(self._rng.choice(others))

    def _schedule_at(self, t_eff: float, cls: int | None) -> None:
        # a newer decision replaces everything scheduled after it
        self._schedule = [(te, c) for te, c in self._schedule if te < t_eff]
        self._schedule.append((t_eff, cls))
