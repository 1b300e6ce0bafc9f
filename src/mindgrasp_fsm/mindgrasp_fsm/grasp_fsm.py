"""The MIndGrasp six-state controller (paper, section Finite State Machine), without ROS.

States: 1 Object Search, 2 Center Object, 3 Initial Approach, 4 Final Approach, 5 Grasp Object,
6 Return to Start. Transitions (paper; ``lock`` = all joints 0 for ``lock_duration`` first, applied
to every change except into or out of state 2):

====  ====  ==========================================================================  =====
from  to    when                                                                        lock
====  ====  ==========================================================================  =====
1     2     both-hands MI with an object of interest in view (autonomous: object seen)  no
2     3     object centred (or centring timed out near it) after state 1 or 3           no
2     4     object centred again after leaving state 4 to recentre                      no
2     1     object lost, or it cannot be centred (joint limit, timeout far off centre)  no
3     2     object of interest drifts out of the centre of the view                     no
3     4     object fills enough of the image, is close in depth, or joint limit near    yes
3     1     object of interest lost                                                     yes
4     2     object off centre before the autonomous approach starts                     no
4     5     gripper at the grasp pose (grasp policy)                                    yes
4     6     object lost or out of reach (abort)                                         yes
5     6     grasp checked by finger effort and lift, or failed after the retries        yes
5     4     fingers not loaded or the object slipped: retry (``grasp_retries``)         yes
6     1     all joints back at the start position (or return timed out)                 yes
====  ====  ==========================================================================  =====

BCI input is used in states 1-3 only; its velocities scale with the certainty. Centring is
proportional on the pixel error, joint 1 from x and the wrist pitch joint (joint 5 of six, 6 of
seven) from y. A watchdog stops every joint when predictions (BCI mode) or joint states are older
than ``watchdog_timeout``, when joint states hold NaN, or when no camera frames arrive; the output
says why. Commands never drive a joint past
its limits, and no joint speeds up faster than ``max_joint_acceleration`` (``return_acceleration``
in state 6); slowing down is never limited, so stops and locks act at once.

A sensor fault (joint states stale, with NaN/inf, or refused by the node for wrong names or
sizes, ``FsmInputs.joint_fault``) latches the stop: the arm holds until the joint states have been
clean for ``sensor_clean_time`` and then, as after a prediction loss, until a fresh decision. The
output's events say when the latch starts and when it is released (both start with
:data:`~mindgrasp_fsm.supervisor.SENSOR_FAULT`); :class:`~mindgrasp_fsm.supervisor.SafetySupervisor`
judges all of this at every tick.

Two BCI paradigms (``paradigm``). ``paper``: the person steers with four classes as in the
paper (left/right hand turn, both hands select and approach, both feet back off). ``scan``
(hybrid shared control, after Xu et al., IEEE TASE 2022): the arm searches by itself as in
autonomous mode and *offers* each object it centres; the person answers yes with both-hands
imagery or no with both-feet imagery, the two classes real EEG tells apart best (0.93 on
EEGMMIDB S001 against 0.60 for left/right hand). Yes commits to the object; no, or no answer
within ``offer_timeout``, lets the arm turn on by ``scan_skip_angle`` to the next object. Once
committed, the arm approaches by itself while the person keeps imagining both hands: a second
yes ("go on", ``affirm_threshold``) must come before the final approach and grasp start (two
decisions on different stretches of EEG, so that one misread stretch cannot grasp the wrong
object), and both feet cancel until the gripper closes (the arm returns to the start and scans
on past that object). Both decisions are taken on evidence accumulated over decoder windows from the
calibrated class probabilities (:mod:`mindgrasp_fsm.evidence`); weak evidence means the arm
waits.

After the MI predictions went stale and came back (``resume_after_stale: require_new_command``,
the default) the arm does not move again by itself: it holds still until a *fresh decision*, one
MI class decoded in every prediction for ``resume_hold`` seconds (by the predictions' stamps),
counting only predictions stamped after the first fresh one that followed the loss, so that no
decision made before the loss carries over. ``resume`` goes on with whatever is decoded.
"""

from __future__ import annotations

import math

import numpy as np

from mindgrasp_common.mi import REST
from mindgrasp_fsm.acceleration import AccelerationLimiter
from mindgrasp_fsm.answer import CLASS_WORDS, resolve_answer
from mindgrasp_fsm.answer import evidence_side as _side
from mindgrasp_fsm.answer import evidence_word as _word
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.evidence import Evidence
from mindgrasp_fsm.grasp_policy import GraspPolicy, PolicyStep, fingers_loaded
from mindgrasp_fsm.kinematics import ArmKinematics
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.supervisor import SafetySupervisor
from mindgrasp_fsm.types import (
    FsmInputs,
    FsmOutput,
    GripperCommand,
    MiClass,
    ObjectObservation,
    State,
    StopKind,
    VisionFrame,
)


def clamp_to_limits(q: np.ndarray, v: np.ndarray, params: FsmParams) -> np.ndarray:
    """Joint velocities (n,) limited to ``max_joint_velocity`` and so that one control period
    cannot carry a joint past ``limit -/+ joint_limit_margin``; moving away from a limit is
    allowed."""
    # np.minimum(np.maximum()) is np.clip's arithmetic without its wrapper (this runs at the
    # control rate)
    v_max = np.asarray(params.max_joint_velocity)
    v = np.minimum(np.maximum(np.asarray(v, dtype=float), -v_max), v_max)
    lo = np.asarray(params.joint_lower_limits) + params.joint_limit_margin
    hi = np.asarray(params.joint_upper_limits) - params.joint_limit_margin
    dt = params.control_period
    up_room = np.maximum(hi - q, 0.0) / dt
    down_room = np.maximum(q - lo, 0.0) / dt
    return np.minimum(np.maximum(v, -down_room), up_room)


def _cap(v: np.ndarray, vmax: np.ndarray | float) -> np.ndarray:
    """Joint velocities (n,) scaled down as one vector so that none exceeds ``vmax`` (rad/s):
    the direction of motion in joint space is kept."""
    scale = float(np.max(np.abs(v) / vmax))
    return v / scale if scale > 1.0 else v


def tilt_direction(kinematics: ArmKinematics | None, home: list[float] | np.ndarray,
                   joint: int) -> float:
    """+1.0 when turning ``joint`` (0-based) positively from ``home`` (n,) rad tilts the camera's
    optical axis back towards the base (as joint 5 of the six-joint arms does), -1.0 when it tilts
    it forward (the Panda's joint 6); +1.0 without a kinematics model."""
    if kinematics is None:
        return 1.0
    q = np.asarray(home, dtype=float)
    dq = np.zeros(q.size)
    dq[joint] = 0.01
    # forward tilt: the optical axis's horizontal component along the direction the arm faces
    # (where the camera is, seen from the base axis: joint 1's zero need not face along x, the
    # Jaco's faces ahead at 2.9 rad)
    (p0, r0), (_, r1) = kinematics.camera_pose(q), kinematics.camera_pose(q + dq)
    facing = np.asarray(p0[:2], dtype=float)
    return 1.0 if float(facing @ (r1[:2, 2] - r0[:2, 2])) <= 0.0 else -1.0


def wrist_tilt(kinematics: ArmKinematics | None, home: list[float] | np.ndarray,
               joint: int) -> bool:
    """True when turning the tilt ``joint`` (0-based) alone does not tilt the camera cleanly at
    ``home`` (n,) rad: its axis lies more than 25 deg off the camera's x axis (a wrist whose
    axes meet at 60 deg, as the Jaco's, turns and rolls the image as much as it tilts it, and
    soon cannot tilt it further). The controller then tilts the camera with the last three
    joints together. False without a kinematics model with a Jacobian."""
    if kinematics is None or not hasattr(kinematics, 'jacobian'):
        return False
    q = np.asarray(home, dtype=float)
    axis = np.asarray(kinematics.jacobian(q))[3:, joint]
    _, rot = kinematics.camera_pose(q)
    across = abs(float(rot[:, 0] @ axis)) / max(float(np.linalg.norm(axis)), 1e-9)
    return across < math.cos(math.radians(25.0))


def pan_direction(kinematics: ArmKinematics | None, home: list[float] | np.ndarray) -> float:
    """+1.0 when turning joint 1 positively from ``home`` (n,) rad turns the arm to its left
    (counterclockwise seen from above: the convention of the search and centring gains), -1.0
    when its axis points down (the Jaco's); +1.0 without a kinematics model."""
    if kinematics is None:
        return 1.0
    q = np.asarray(home, dtype=float)
    dq = np.zeros(q.size)
    dq[0] = 0.01
    (p0, _), (p1, _) = kinematics.camera_pose(q), kinematics.camera_pose(q + dq)
    return 1.0 if float(p0[0] * p1[1] - p0[1] * p1[0]) >= 0.0 else -1.0


class GraspFsm:
    """Six-state semi-autonomous grasp controller; call :meth:`tick` at the control rate.

    Parameters
    ----------
    params : FsmParams
        Gains and thresholds (``config/param/fsm.yaml``).
    kinematics : ArmKinematics or None
        Robot model for the autonomous final approach (camera pose and grasp IK). Without it the
        controller aborts state 4 and returns to start.
    """

    def __init__(self, params: FsmParams | None = None,
                 kinematics: ArmKinematics | None = None) -> None:
        self.params = params or FsmParams()
        #: arm joints (6 or 7); every velocity this controller sends has this many
        self.n_joints = len(self.params.joint_names)
        # the wrist pitch joint that tilts the camera (0-based): the second to last, joint 5
        # of a six-joint arm, joint 6 of a seven-joint one (the last joint rolls the hand)
        self.tilt_joint = self.n_joints - 2
        self.kinematics = kinematics
        # +1 when a positive tilt-joint velocity tilts the camera down towards the base (the
        # gains' and the search tilts' convention), -1 when the arm's joint turns the other way
        self.tilt_sign = tilt_direction(kinematics, self.params.home_position, self.tilt_joint)
        # +1 when a positive joint-1 velocity turns the arm left (the gains' convention), -1 when
        # joint 1's axis points down
        self.pan_sign = pan_direction(kinematics, self.params.home_position)
        self.wrist_tilt = wrist_tilt(kinematics, self.params.home_position, self.tilt_joint)
        self.policy = GraspPolicy(self.params, kinematics)
        #: the scan paradigm's answer pair in force and the model's decision thresholds (nat s)
        self.answer, self._model_thresholds = resolve_answer(self.params)
        self.reset()

    @classmethod
    def from_params(cls, params: FsmParams | None = None) -> GraspFsm:
        """Controller with the robot model named by ``params.urdf_file`` (URDF)."""
        from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
        from mindgrasp_common.robot_description import load_robot
        from mindgrasp_fsm.kinematics import UrdfKinematics, frame_offset

        params = params or FsmParams()
        offsets = {}
        if params.robot:
            # the description's TCP offset and camera mount (params.__post_init__ checked it)
            robot = load_robot(params.robot)
            offsets = {'tool_offset': frame_offset(robot.tcp.xyz, robot.tcp.rpy),
                       'camera_offset': frame_offset(robot.camera.xyz, robot.camera.rpy)}
        try:
            urdf = resolve_path(params.urdf_file, 'mindgrasp_fsm')
        except ResourceNotFoundError as exc:
            msg = f'Cannot read the robot description {params.urdf_file}: {exc}'
            raise FsmError(msg) from None
        kinematics = UrdfKinematics(str(urdf), params.joint_names, params.tool_link,
                                    params.camera_link, **offsets, home=params.home_position)
        return cls(params, kinematics)

    # ---------------------------------------------------------------------------- lifecycle
    def reset(self, time: float = 0.0) -> None:
        """Back to Object Search, gripper open, no locks, all timers cleared."""
        self.state = State.OBJECT_SEARCH
        self.previous_state = State.OBJECT_SEARCH
        self.reason = 'started'
        self._clock = time            # active clock: wall/sim time minus time spent stopped
        self._now = time              # the inputs' time of this tick (the predictions' clock)
        self._last_time: float | None = None
        self._state_since = 0.0
        self._lock_until: float | None = None
        self._pending: tuple[State, str] | None = None
        self._center_next = State.INITIAL_APPROACH
        self._centred_since: float | None = None
        self._last_seen: float | None = None
        self._seen_since: float | None = None
        self._ooi: ObjectObservation | None = None
        self._ooi_label = ''
        self._sweep = 0
        self._sweep_dir = 1.0
        self._ignore_from: float | None = None
        self._ignore_angle = self.params.search_ignore_angle
        self._gave_up_at = -math.inf
        self._both_since: float | None = None   # since when both-hands is decoded without break
        #: what may move at each tick: input ages, start-up, sensor latch, fresh decisions
        self.supervisor = SafetySupervisor(self.params, self.n_joints)
        self._dt = 0.0
        self._limiter = AccelerationLimiter(self.n_joints)
        self._return_lift: bool | None = None
        # scan paradigm: when the current offer began (None: no offer), whether the person
        # committed to the object of interest, and the evidence of each decision
        self._offer_since: float | None = None
        self._committed = False
        # scan: bearings (joint-1 angle facing them, rad) of the objects passed or cancelled in
        # this scan, and the ends of the joint-1 range reached since the first of them
        self._passed: list[float] = []
        self._limits_reached: set[float] = set()
        yes, no = _side(self.answer.yes), _side(self.answer.no)
        th = self.decision_thresholds()
        self._confirm = Evidence(yes, list(self.answer.no), threshold=th['confirm'],
                                 clip=self.params.evidence_clip, reject_threshold=th['pass'])
        # cancel and go-on are the two answers of one test during the approach
        self._cancel = Evidence(no, list(self.answer.yes), threshold=th['cancel'],
                                clip=self.params.evidence_clip, reject_threshold=th['affirm'])
        self._affirmed = False
        self._attempt = 0
        self._outcome = ''
        self._gripper = GripperCommand(self.params.gripper_open_position, 0.0)
        self._events: list[str] = []
        self.policy = GraspPolicy(self.params, self.kinematics)

    def decision_thresholds(self) -> dict[str, float]:
        """The scan decisions' thresholds in force (nat s): ``confirm``, ``pass``, ``affirm``,
        ``cancel``; the classifier model's (per person) when it has them and
        ``model_thresholds`` is set, else the parameters."""
        p = self.params
        th = {'confirm': p.confirm_threshold, 'pass': p.pass_threshold,
              'affirm': p.affirm_threshold, 'cancel': p.cancel_threshold}
        if p.model_thresholds and self._model_thresholds:
            th.update({k: v for k, v in self._model_thresholds.items() if k in th})
        return th

    def force_state(self, state: State | int, reason: str = 'set by the caller',
                    center_next: State | int | None = None, attempt: int = 0) -> None:
        """Jump to ``state`` at once, without a lock, running its entry actions (tests, tools).

        ``center_next``: where Center Object goes when centred; ``attempt``: grasp retries used.
        """
        self._lock_until = None
        self._pending = None
        if center_next is not None:
            self._center_next = State(center_next)
        self._attempt = int(attempt)
        self._enter(State(state), reason)

    # ---------------------------------------------------------------------------- transitions
    def _goto(self, new: State, reason: str) -> None:
        """Change state; lock first unless the change is into or out of Center Object."""
        if State.CENTER_OBJECT in (new, self.state):
            self._enter(new, reason)
            return
        self._lock_until = self._clock + self.params.lock_duration
        self._pending = (new, reason)
        self._events.append(f'lock {int(self.state)}->{int(new)}: {reason}')

    def _enter(self, new: State, reason: str) -> None:
        self.previous_state = self.state
        self.state = new
        self.reason = reason
        self._state_since = self._clock
        self._centred_since = None
        self._events.append(f'enter {int(new)} from {int(self.previous_state)}: {reason}')
        if new == State.CENTER_OBJECT and self.previous_state == State.OBJECT_SEARCH:
            self._outcome = ''        # a new object was selected: a new grasp begins
        if new == State.OBJECT_SEARCH:
            self._seen_since = None
            self._attempt = 0
            self._committed = False
            self._offer_since = None

        elif new == State.FINAL_APPROACH:
            shape = self._ooi.shape if self._ooi is not None else 'unknown'
            self.policy.begin_approach(self._clock, shape, self._attempt)
            self._gripper = self.policy.gripper
        elif new == State.GRASP_OBJECT:
            self.policy.begin_grasp(self._clock)
            self._gripper = self.policy.gripper
        elif new == State.RETURN_TO_START:
            self._return_lift = None
            self._gripper = self.policy.gripper if self._outcome == 'holding' else \
                GripperCommand(self.params.gripper_open_position, 0.0)

    # ---------------------------------------------------------------------------- outputs
    def _output(self, v: np.ndarray, *, stop_kind: StopKind = StopKind.NONE,
                reason: str | None = None, phase: str = '') -> FsmOutput:
        events, self._events = self._events, []
        if reason is None and self._pending is not None:
            reason = f'locked: {self._pending[1]}'
        p = self.params
        accel = np.asarray(p.max_joint_acceleration, dtype=float)
        if self.state == State.RETURN_TO_START:
            accel = np.minimum(accel, p.return_acceleration)
        v = self._limiter.limit(v, self._dt, accel)
        self.policy.sent(self._now, v)     # where the commands put the arm (grasp policy)
        if v.any():
            # the arm moves: from now on an old input is a fault (latched), never a late start
            self.supervisor.arm_moved()
        return FsmOutput(
            joint_velocities=v, gripper=self._gripper, state=self.state,
            previous_state=self.previous_state, locked=self._lock_until is not None,
            stopped=stop_kind != StopKind.NONE, stop_kind=stop_kind,
            reason=self.reason if reason is None else reason,
            object_of_interest=self._ooi_label, phase=phase, grasp_attempts=self._attempt,
            grasp_outcome=self._outcome, events=events,
            paradigm='autonomous' if self.params.autonomous else self.params.paradigm,
            offered=self._offer_since is not None,
            confirm_evidence=self._confirm.fraction if self._offer_since is not None else 0.0,
            cancel_evidence=self._cancel.fraction if self._cancellable() else 0.0)

    @property
    def _scan(self) -> bool:
        return not self.params.autonomous and self.params.paradigm == 'scan'

    def _cancellable(self) -> bool:
        """Scan: the committed approach may still be cancelled (the gripper has not closed)."""
        return self._scan and self._committed and self.state in (
            State.CENTER_OBJECT, State.INITIAL_APPROACH, State.FINAL_APPROACH)

    def _stop(self, kind: StopKind, why: str) -> FsmOutput:
        return self._output(np.zeros(self.n_joints), stop_kind=kind, reason=why)

    # ---------------------------------------------------------------------------- main tick
    def tick(self, inputs: FsmInputs) -> FsmOutput:
        """Advance the controller to ``inputs.time`` (s) and return the commands of this tick."""
        p = self.params
        now = float(inputs.time)
        if not math.isfinite(now):
            msg = f'The controller time must be finite seconds, got {now}; pass the clock time.'
            raise FsmError(msg)
        first = self._last_time is None
        dt = 0.0 if first else max(now - self._last_time, 0.0)
        self._last_time = now
        self._now = now
        # the speed-up allowed this tick: one control period at most, so that a late tick (a
        # loaded machine) cannot step the velocity further than a punctual one
        self._dt = p.control_period if first else min(dt, p.control_period)

        # --- watchdog: nothing moves on stale or broken inputs -------------------------------
        kind, why = self.supervisor.check(inputs, now)
        self._events += self.supervisor.take_events()
        if why:
            return self._stop(kind, why)    # the active clock does not advance while stopped
        self._clock += dt
        t = self._clock
        assert inputs.joints is not None
        q = np.asarray(inputs.joints.position, dtype=float)
        # the motion of states 4-6 is bounded by how old the joint states are (grasp policy)
        self.policy.observe(now, inputs.joints.stamp, inputs.joints.velocity)

        self._observe(inputs.vision, t)

        # --- lock between states ------------------------------------------------------------
        if self._lock_until is not None:
            if t < self._lock_until:
                return self._output(np.zeros(self.n_joints))
            self._lock_until = None
            assert self._pending is not None
            new, reason = self._pending
            self._pending = None
            self._enter(new, reason)

        if self._cancellable():
            th = self.decision_thresholds()
            self._cancel.threshold, self._cancel.clip = th['cancel'], p.evidence_clip
            self._cancel.reject_threshold = th['affirm']
            if self._cancel.update(inputs.prediction):
                self._cancel_approach(q, f'cancelled the approach to the {self._ooi_label} '
                                      f'({_word(self.answer.no)} evidence '
                                      f'{self._cancel.value:.2f} nat s)')
                return self._output(np.zeros(self.n_joints), phase='cancelled')
            if self._cancel.rejected and not self._affirmed:
                self._affirmed = True
                self._events.append(f'go on with the {self._ooi_label} '
                                    f'({_word(self.answer.yes)} evidence '
                                    f'{-self._cancel.value:.2f} nat s)')

        handler = {
            State.OBJECT_SEARCH: self._search,
            State.CENTER_OBJECT: self._center,
            State.INITIAL_APPROACH: self._initial_approach,
            State.FINAL_APPROACH: self._final_approach,
            State.GRASP_OBJECT: self._grasp,
            State.RETURN_TO_START: self._return,
        }[self.state]
        v, phase = handler(t, q, inputs)
        if self._lock_until is not None:   # a transition asked for a lock: stop this tick
            v = np.zeros(self.n_joints)
        return self._output(clamp_to_limits(q, v, p), phase=phase)

    def _observe(self, vision: VisionFrame | None, t: float) -> None:
        ooi = vision.object_of_interest if vision is not None else None
        if ooi is not None:
            self._ooi = ooi
            self._ooi_label = ooi.label
            self._last_seen = t
            self._seen_since = self._seen_since if self._seen_since is not None else t
        else:
            self._seen_since = None

    def _visible(self, inputs: FsmInputs) -> ObjectObservation | None:
        return inputs.vision.object_of_interest if inputs.vision is not None else None

    def _errors(self, ooi: ObjectObservation, vision: VisionFrame) -> tuple[float, float]:
        """Normalised centring errors (px error / image size), x right and y down positive."""
        ex = (ooi.centre_x - vision.image_width / 2.0) / vision.image_width
        ey = (ooi.centre_y - vision.image_height / 2.0) / vision.image_height
        return ex, ey

    def _centring(self, ooi: ObjectObservation, vision: VisionFrame, gain_scale: float,
                  q: np.ndarray) -> np.ndarray:
        p = self.params
        ex, ey = self._errors(ooi, vision)
        v = np.zeros(self.n_joints)
        v[0] = self.pan_sign * p.center_sign_joint1 * p.center_gain_joint1 * gain_scale * ex
        tilt = p.center_sign_joint5 * p.center_gain_joint5 * gain_scale * ey
        if self.wrist_tilt and self.kinematics is not None:
            # the camera turned about its own x axis at the rate the tilt joint alone turns
            # it on the other arms (-tilt rad/s), by the last three joints together
            _, rot = self.kinematics.camera_pose(q)
            jac = np.asarray(self.kinematics.jacobian(q))[3:, -3:]
            v[-3:] = np.linalg.lstsq(jac, -tilt * rot[:, 0], rcond=None)[0]
        else:
            v[self.tilt_joint] = self.tilt_sign * tilt
        return v

    def _certainty(self, inputs: FsmInputs) -> tuple[int, float]:
        pred = inputs.prediction
        if pred is None or self.params.autonomous:
            return -1, 0.0
        if pred.class_index == REST:
            return REST, 0.0              # no imagery: no command, as a class below threshold
        cert = float(pred.certainty)
        if not math.isfinite(cert):
            cert = 0.0
        return int(pred.class_index), min(max(cert, 0.0), self.params.certainty_cap)

    def _lost(self, t: float) -> bool:
        seen = self._state_since if self._last_seen is None else max(self._last_seen,
                                                                       self._state_since)
        return t - seen > self.params.object_lost_timeout

    # ---------------------------------------------------------------------------- state 1
    def _search(self, t: float, q: np.ndarray, inputs: FsmInputs) -> tuple[np.ndarray, str]:
        p = self.params
        v = np.zeros(self.n_joints)
        g = inputs.gripper
        loaded = fingers_loaded(g, p.finger_contact_effort) if g is not None else None
        empty = loaded == 0 if loaded is not None else \
            g is not None and (g.fingers_in_contact == 0 or g.contact is False)
        if self._gripper.position != p.gripper_open_position and empty:
            # closed on nothing (the scene was reset under the hand, or the object fell):
            # the fingers only hide the camera's view, so open them
            self._gripper = GripperCommand(p.gripper_open_position, 0.0)
        ooi = self._visible(inputs)
        if p.autonomous or self._scan:
            if self._ignore_from is not None:
                if abs(q[0] - self._ignore_from) < self._ignore_angle:
                    return self._sweep_step(q), 'turning away from an object out of reach' \
                        if p.autonomous else 'turning on to the next object'
                self._ignore_from = None
                self._seen_since = None
            if ooi is not None and self._scan and self._was_passed(ooi, q, inputs):
                # offered (or cancelled) in this scan already: the others come first
                self._seen_since = None
                return self._sweep_step(q), f'turning on past the {ooi.label}'
            if ooi is not None and self._seen_since is not None \
                    and t - self._seen_since >= p.search_confirm_time:
                self._center_next = State.INITIAL_APPROACH
                found = 'autonomous search' if p.autonomous else 'scan'
                self._goto(State.CENTER_OBJECT, f'{ooi.label} seen by the {found}')
                return v, 'found'
            if ooi is not None:
                return v, 'confirming'
            return self._sweep_step(q), f'sweep {self._sweep}'
        cls, cert = self._certainty(inputs)
        if cls != MiClass.BOTH_HANDS:
            self._both_since = None
        elif self._both_since is None:
            self._both_since = t
        if cls == MiClass.LEFT_HAND:
            v[0] = self.pan_sign * p.search_gain * cert
        elif cls == MiClass.RIGHT_HAND:
            v[0] = -self.pan_sign * p.search_gain * cert
        elif cls == MiClass.BOTH_HANDS:
            if ooi is not None and self._ignore_from is not None and \
                    abs(q[0] - self._ignore_from) < p.bci_reselect_angle and \
                    t - self._gave_up_at < p.bci_reselect_delay:
                # it could not be centred from here: without this, selecting it again at once
                # flips between states 1 and 2 every tick
                return v, f'the {ooi.label} cannot be centred from here: turn left or right'
            if ooi is not None and t - self._both_since < p.bci_select_dwell:
                return v, f'both hands for {t - self._both_since:.2f} s'
            if ooi is not None:
                self._ignore_from = None
                self._center_next = State.INITIAL_APPROACH
                self._goto(State.CENTER_OBJECT, f'both-hands MI selected the {ooi.label}')
                return v, 'selected'
            return v, 'both hands but no object in view'
        return v, CLASS_WORDS.get(cls, 'no class')

    def _sweep_step(self, q: np.ndarray) -> np.ndarray:
        """Autonomous search: turn left; at a joint-1 limit change the camera tilt, turn back."""
        p = self.params
        v = np.zeros(self.n_joints)
        tilts = p.autonomous_search_tilts or [0.0]
        tilt = tilts[self._sweep % len(tilts)]
        lo = p.joint_lower_limits[0] + p.joint_limit_margin + 0.05
        hi = p.joint_upper_limits[0] - p.joint_limit_margin - 0.05
        if (self._sweep_dir > 0 and q[0] >= hi) or (self._sweep_dir < 0 and q[0] <= lo):
            self._sweep += 1
            self._sweep_dir = -self._sweep_dir
            # scan: once both ends were reached since the first pass, every object has been
            # offered once; the next sweep offers them all again
            self._limits_reached.add(self._sweep_dir)
            if len(self._limits_reached) == 2:
                self._passed.clear()
                self._limits_reached.clear()
        v[0] = self._sweep_dir * p.autonomous_search_velocity
        home = np.asarray(p.home_position)
        # keep the other joints at home, the wrist pitch joint at this sweep's tilt
        target = home.copy()
        target[self.tilt_joint] = home[self.tilt_joint] + self.tilt_sign * tilt
        err = target - q
        err[0] = 0.0
        v[1:] = np.clip(p.return_gain * err[1:], -0.5, 0.5)
        return v

    # ---------------------------------------------------------------------------- state 2
    def _center(self, t: float, q: np.ndarray, inputs: FsmInputs) -> tuple[np.ndarray, str]:
        p = self.params
        ooi = self._visible(inputs)
        if ooi is None:
            if self._lost(t):
                self._goto(State.OBJECT_SEARCH, 'object of interest lost while centring')
            return np.zeros(self.n_joints), 'object not in this frame'
        assert inputs.vision is not None
        ex, ey = self._errors(ooi, inputs.vision)
        v = self._centring(ooi, inputs.vision, 1.0, q)
        if self._offer_since is not None:
            return self._offer(t, q, inputs, ooi, v)
        if abs(ex) < p.center_tolerance and abs(ey) < p.center_tolerance:
            self._centred_since = self._centred_since if self._centred_since is not None else t
            if t - self._centred_since >= p.center_hold_time:
                if self._scan and not self._committed and \
                        self._center_next == State.INITIAL_APPROACH:
                    return self._offer(t, q, inputs, ooi, v)
                self._goto(self._center_next, f'{ooi.label} centred')
                return np.zeros(self.n_joints), 'centred'
        else:
            self._centred_since = None
        blocked = self._blocked_joint(q, v)
        if blocked:
            # the object lies beyond a joint limit this way round: search the other way
            self._give_up_on_object(q, v, f'joint {blocked} is at its limit, the {ooi.label} '
                                    'cannot be centred; searching the other way')
            return np.zeros(self.n_joints), 'limit'
        if t - self._state_since > p.center_timeout:
            if max(abs(ex), abs(ey)) <= p.recenter_threshold:
                self._goto(self._center_next, f'centring timed out after {p.center_timeout:.1f} s'
                           ' (object near the centre)')
            else:
                self._give_up_on_object(q, v, f'the {ooi.label} could not be centred in '
                                        f'{p.center_timeout:.1f} s; searching again')
            return np.zeros(self.n_joints), 'timeout'
        return v, f'error x {ex:+.3f} y {ey:+.3f}'

    def _blocked_joint(self, q: np.ndarray, v: np.ndarray) -> int:
        """Joint number (1 or 5) whose centring command pushes into its limit, else 0."""
        p = self.params
        for j in (0, 4):
            near_hi = q[j] >= p.joint_upper_limits[j] - p.joint_limit_margin - 0.03
            near_lo = q[j] <= p.joint_lower_limits[j] + p.joint_limit_margin + 0.03
            if (near_hi and v[j] > 1e-3) or (near_lo and v[j] < -1e-3):
                return j + 1
        return 0

    def _give_up_on_object(self, q: np.ndarray, v: np.ndarray, reason: str) -> None:
        """Back to Object Search; the autonomous sweep turns away from the object it could not
        centre and ignores objects until joint 1 has turned ``search_ignore_angle``."""
        if abs(v[0]) > 1e-3:
            self._sweep_dir = -float(np.sign(v[0]))
        self._ignore_from = float(q[0])
        self._ignore_angle = self.params.search_ignore_angle
        self._gave_up_at = self._clock
        self._offer_since = None
        self._goto(State.OBJECT_SEARCH, reason)

    # ---------------------------------------------------------------------------- scan
    def _offer(self, t: float, q: np.ndarray, inputs: FsmInputs, ooi: ObjectObservation,
               v: np.ndarray) -> tuple[np.ndarray, str]:
        """Scan, state 2: the centred object is offered; commit on both-hands evidence, pass
        on on both-feet evidence or after ``offer_timeout``. The arm keeps the object centred
        meanwhile."""
        p = self.params
        if self._offer_since is None:
            self._offer_since = t
            self._confirm.reset(self._now + p.offer_delay)
            self._events.append(f'offering the {ooi.label}')
        th = self.decision_thresholds()
        self._confirm.threshold, self._confirm.clip = th['confirm'], p.evidence_clip
        self._confirm.reject_threshold = th['pass']
        if self._confirm.update(inputs.prediction):
            self._committed = True
            self._affirmed = False
            self._offer_since = None
            # the go-on decision counts windows after those of the confirmation only
            self._cancel.reset(self._now + p.offer_delay)
            self._goto(self._center_next, f'confirmed the {ooi.label} '
                       f'({_word(self.answer.yes)} evidence {self._confirm.value:.2f} nat s)')
            return np.zeros(self.n_joints), 'confirmed'
        declined = self._confirm.rejected
        if declined or t - self._offer_since > p.offer_timeout:
            self._offer_since = None
            self._remember_passed(q)
            why = (f'declined ({_word(self.answer.no)} evidence {-self._confirm.value:.2f} '
                   'nat s)' if declined
                   else f'not confirmed in {p.offer_timeout:.1f} s')
            self._goto(State.OBJECT_SEARCH, f'passed the {ooi.label}: {why}')
            return np.zeros(self.n_joints), 'passed'
        return v, f'offering the {ooi.label}: evidence {self._confirm.fraction:.0%}'

    def _bearing(self, ooi: ObjectObservation, q: np.ndarray, inputs: FsmInputs) -> float:
        """Joint-1 angle (rad) at which the arm would face ``ooi``: the current one plus the
        object's horizontal angle in the image (pinhole camera; turning towards an object right
        of centre is ``center_sign_joint1`` times :attr:`pan_sign`)."""
        cam = inputs.camera
        if cam is None or inputs.vision is None:
            return float(q[0])
        off = math.atan2(ooi.centre_x - inputs.vision.image_width / 2.0, cam.fx)
        return float(q[0]) + self.pan_sign * self.params.center_sign_joint1 * off

    def _was_passed(self, ooi: ObjectObservation, q: np.ndarray, inputs: FsmInputs) -> bool:
        bearing = self._bearing(ooi, q, inputs)
        return any(abs(bearing - b) < self.params.scan_skip_angle for b in self._passed)

    def _remember_passed(self, q: np.ndarray) -> None:
        if not self._passed:
            self._limits_reached.clear()
        self._passed.append(float(q[0]))

    def _cancel_approach(self, q: np.ndarray, reason: str) -> None:
        """Scan: back out of the approach (both-feet evidence, or no go-on in time): return to
        the start, then scan on past this object. ``reason`` starts with 'cancelled'."""
        self._outcome = 'cancelled'
        self._committed = False
        self._remember_passed(q)
        self._goto(State.RETURN_TO_START, reason)

    # ---------------------------------------------------------------------------- state 3
    def _initial_approach(self, t: float, q: np.ndarray, inputs: FsmInputs
                          ) -> tuple[np.ndarray, str]:
        p = self.params
        v = np.zeros(self.n_joints)
        ooi = self._visible(inputs)
        if ooi is None:
            if self._lost(t):
                self._goto(State.OBJECT_SEARCH, 'object of interest lost during the approach')
            return v, 'object not in this frame'
        assert inputs.vision is not None
        ex, ey = self._errors(ooi, inputs.vision)
        if max(abs(ex), abs(ey)) > p.recenter_threshold:
            self._center_next = State.INITIAL_APPROACH
            self._goto(State.CENTER_OBJECT, f'{ooi.label} drifted off centre during the approach')
            return v, 'recentre'
        j = p.approach_joint - 1
        near_limit = (p.approach_sign > 0 and q[j] >= p.joint_upper_limits[j] - 0.1) or \
            (p.approach_sign < 0 and q[j] <= p.joint_lower_limits[j] + 0.1)
        close = ooi.pixel_fraction > p.final_approach_pixel_fraction or near_limit or (
            math.isfinite(ooi.distance) and ooi.distance < p.final_approach_distance)
        if close and self._scan and not self._affirmed:
            # scan: the final approach and grasp wait for the person's go-on; none in time
            # means the arm backs out, never that it grasps
            if t - self._state_since > p.offer_timeout:
                self._cancel_approach(q, f'cancelled the approach to the {ooi.label}: no go-on '
                                      f'within {p.offer_timeout:.1f} s')
                return v, 'cancelled'
            return (self._centring(ooi, inputs.vision, p.approach_center_gain, q),
                    'waiting for go-on')
        if ooi.pixel_fraction > p.final_approach_pixel_fraction:
            self._goto(State.FINAL_APPROACH, f'{ooi.label} fills {100 * ooi.pixel_fraction:.1f} %'
                       ' of the image')
            return v, 'close'
        if math.isfinite(ooi.distance) and ooi.distance < p.final_approach_distance:
            self._goto(State.FINAL_APPROACH, f'{ooi.label} is {ooi.distance:.2f} m away')
            return v, 'close'
        if near_limit:
            self._goto(State.FINAL_APPROACH, f'joint {p.approach_joint} near its limit')
            return v, 'limit'
        cls, cert = self._certainty(inputs)
        if p.autonomous or self._scan or cert <= p.certainty_threshold:
            v += self._centring(ooi, inputs.vision, p.approach_center_gain, q)
            v[j] = p.approach_sign * p.default_approach_velocity
            return v, 'default approach'
        if cls == MiClass.LEFT_HAND:
            v[0] = self.pan_sign * p.turn_gain * cert
            return v, 'turn left'
        if cls == MiClass.RIGHT_HAND:
            v[0] = -self.pan_sign * p.turn_gain * cert
            return v, 'turn right'
        if cls == MiClass.BOTH_FEET:
            v[j] = -p.approach_sign * p.retreat_gain * cert
            return v, 'back off'
        v += self._centring(ooi, inputs.vision, p.approach_center_gain, q)
        v[j] = p.approach_sign * p.approach_gain * cert
        return v, 'approach'

    # ---------------------------------------------------------------------------- states 4, 5
    def _final_approach(self, t: float, q: np.ndarray, inputs: FsmInputs
                        ) -> tuple[np.ndarray, str]:
        p = self.params
        ooi = self._visible(inputs)
        if self.policy.phase in ('open', 'measure') and self._attempt == 0 and ooi is not None:
            assert inputs.vision is not None
            ex, ey = self._errors(ooi, inputs.vision)
            if max(abs(ex), abs(ey)) > p.recenter_threshold:
                self._center_next = State.FINAL_APPROACH
                self._goto(State.CENTER_OBJECT, f'{ooi.label} off centre before the final approach')
                return np.zeros(self.n_joints), 'recentre'
        step = self.policy.approach_step(t, q, inputs.vision, inputs.camera, inputs.gripper)
        self._gripper = step.gripper
        if step.event == 'at_grasp_pose':
            self._goto(State.GRASP_OBJECT, step.reason)
        elif step.event == 'abort':
            self._outcome = 'failed'
            self._goto(State.RETURN_TO_START, f'final approach aborted: {step.reason}')
        return step.velocities, step.phase

    def _grasp(self, t: float, q: np.ndarray, inputs: FsmInputs) -> tuple[np.ndarray, str]:
        step: PolicyStep = self.policy.grasp_step(t, q, inputs.gripper)
        self._gripper = step.gripper
        if step.event == 'grasped':
            self._outcome = 'holding'
            self._goto(State.RETURN_TO_START, step.reason)
        elif step.event == 'retry':
            self._attempt += 1
            self._goto(State.FINAL_APPROACH, f'retrying the grasp: {step.reason}')
        elif step.event == 'failed':
            self._outcome = 'failed'
            self._goto(State.RETURN_TO_START, f'grasp failed: {step.reason}')
        return step.velocities, step.phase

    # ---------------------------------------------------------------------------- state 6
    def _return(self, t: float, q: np.ndarray, inputs: FsmInputs) -> tuple[np.ndarray, str]:
        p = self.params
        holding = self._outcome == 'holding'
        if holding and self.kinematics is not None and self._return_lift is None:
            tool = self.kinematics.tool_position(q)
            self._return_lift = max(p.return_lift_height - float(tool[2]), 0.0) > 0.01
            if self._return_lift:
                target = tool.copy()
                target[2] = p.return_lift_height
                self.policy.start_lift(t, q, target)
        if holding and self._return_lift:
            # carrying: rise straight up first, so the object clears the table and the arm
            v, done = self.policy.lift_step(t, q)
            if not done:
                return _cap(v, p.return_velocity_holding), 'lifting'
            self._return_lift = False
        err = np.asarray(p.home_position) - q
        if np.max(np.abs(err)) < p.return_tolerance:
            self._goto(State.OBJECT_SEARCH, 'returned to the start position')
            return np.zeros(self.n_joints), 'home'
        if t - self._state_since > p.return_timeout:
            self._goto(State.OBJECT_SEARCH, f'return timed out after {p.return_timeout:.1f} s')
            return np.zeros(self.n_joints), 'timeout'
        v = p.return_gain * err
        vmax = np.asarray(p.max_joint_velocity)
        if holding:
            vmax = np.minimum(vmax, p.return_velocity_holding)
        # the speed-up to this is ramped by the acceleration limiter (_output)
        return _cap(v, vmax), 'returning'

    # ---------------------------------------------------------------------------- info
    @property
    def outcome(self) -> str:
        """'' while no grasp has finished, 'holding' after a checked grasp, 'failed' otherwise."""
        return self._outcome
