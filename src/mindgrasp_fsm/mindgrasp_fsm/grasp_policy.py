"""The autonomous part of the controller: final approach (state 4) and grasp (state 5).

The paper closed the gripper when the object filled enough of the image and lifted by returning
home; it grasped 33.5 % of random placements. This policy places the gripper from a depth
measurement instead:

1. ``open``: open the hand and hold still so the depth image is sharp.
2. ``measure``: the object of interest's centre pixel and depth, back-projected with the camera
   intrinsics and the camera pose (forward kinematics), give its position on the table (median
   over ``measure_frames`` camera frames: a real depth camera scatters); the shape (depth CNN)
   gives its size, pre-grasp height, grasp height and wrist yaw.
3. ``to_pregrasp``: joint-space move (inverse kinematics) to a point straight above the object, the
   gripper pointing down.
4. ``refine``: closed-loop re-centring above the object: from above the camera sees the top
   face; the position is measured again and the pre-grasp corrected until the correction is
   below 4 mm (parallax from the oblique first view and noise are the errors it removes).
5. ``descend``: straight down to the grasp height.
6. ``close`` (state 5): force-limited closing until the fingers stall.
7. ``check_contact``: every finger must push on something (finger effort; a real hand's contact
   sensor cannot tell the object from the table) and the hand must not be fully closed; with
   ``grasp_check: width`` (a parallel-jaw gripper) the jaws, closing with the full command, must
   have stopped apart.
8. ``lift`` + ``check_lift``: lift and check the finger efforts and opening again (an object
   that slipped out unloads the fingers; ``min_fingers_holding`` still carry it); a slip or a
   miss opens the hand,
   backs off and retries once (``grasp_retries``), from a new measurement.

All motions are joint velocities (rad/s), within joint limits and velocity limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mindgrasp_common.geometry import wrap_angle
from mindgrasp_fsm.kinematics import ArmKinematics
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import CameraModel, GripperCommand, GripperState, VisionFrame

#: closing fingers that have not moved for this long (s) have stopped on the object (or shut)
FINGER_STALL_TIME = 0.2


@dataclass
class PolicyStep:
    """One tick of the policy: joint velocities (n,) rad/s, gripper command, event, phase."""

    velocities: np.ndarray
    gripper: GripperCommand
    phase: str
    event: str = ''     # '', 'at_grasp_pose', 'grasped', 'retry', 'failed', 'abort'
    reason: str = ''


def estimate_object_position(obs_centre: tuple[float, float], distance: float, bbox_width: float,
                             camera: CameraModel, cam_pos: np.ndarray, cam_rot: np.ndarray,
                             size: float, table_height: float) -> tuple[np.ndarray, np.ndarray]:
    """Object centre (m, base frame) from its centre pixel, depth and the camera pose.

    ``distance`` is the depth (m, along the optical axis) of the object's visible surface; when
    it is NaN the pinhole size relation ``depth = fx * size / bbox_width`` stands in, as the paper
    did. The visible surface lies ``size / 2`` in front of the centre along the viewing ray; the
    height is set from the table and the object size (objects rest on the table).

    Returns ``(centre, surface)``: the estimated centre and the measured surface point (m, base
    frame); seen from above, the surface point's height is the object's top.
    """
    u, v = obs_centre
    depth = float(distance)
    if not math.isfinite(depth) or depth <= 0:
        depth = camera.fx * size / max(float(bbox_width), 1.0)
    p_cam = camera.backproject(u, v, depth)
    p = cam_pos + cam_rot @ p_cam
    surface = p.copy()
    ray = p - cam_pos
    norm = float(np.linalg.norm(ray))
    if norm > 1e-9:
        p = p + ray / norm * (size / 2.0)
    p[2] = table_height + size / 2.0
    return p, surface


def fingers_loaded(gripper: GripperState, min_effort: float) -> int | None:
    """How many fingers push on something (|effort| >= ``min_effort`` N m), or None when the
    gripper reports no efforts (or ``min_effort`` is 0: use the contact flags)."""
    if min_effort <= 0 or gripper.efforts is None:
        return None
    efforts = np.abs(np.asarray(gripper.efforts, dtype=float))
    if not np.all(np.isfinite(efforts)):
        return None
    return int(np.count_nonzero(efforts >= min_effort))


class GraspPolicy:
    """Sub-state machine for the final approach and the grasp. No ROS, no simulator access."""

    def __init__(self, params: FsmParams, kinematics: ArmKinematics | None) -> None:
        self.params = params
        self.kinematics = kinematics
        self.phase = ''
        self.shape = 'unknown'
        self.object_position: np.ndarray | None = None   # m, base frame (object centre)
        self.object_height: float | None = None          # m, measured from above
        self.attempt = 0
        self._t0 = 0.0
        self._q_target: np.ndarray | None = None
        self._line: tuple[np.ndarray, np.ndarray, float, float] | None = None  # p0, p1, t0, T
        self._yaw = 0.0
        self._tilt = 0.0          # rad, the tool's lean towards the base (0: vertical)
        self._refinements = 0
        self._gripper = GripperCommand(params.gripper_open_position, 0.0)
        self._last_opening: tuple[float, float, float] | None = None  # (t, stamp, opening)
        self._stall_since: float | None = None
        self._contact_since: float | None = None   # all fingers touching since (s)
        self._hold_since: float | None = None      # compliant hold commanded since (s)
        self._opening_at_close: float | None = None  # the first opening read while closing
        self._after_retreat = ''
        self._retreat_reason = ''
        self._lost_since: float | None = None
        self._samples: list[tuple[float, np.ndarray, float | None]] = []   # (stamp, centre, h)
        #: age (s) of the joint states this tick's motion is computed from; the controller sets
        #: it every tick (:meth:`observe`)
        self.input_age = 0.0
        self._input_time = (0.0, 0.0)    # (now, joint-state stamp), s of the inputs' clock
        self._seen_velocity = self._zeros()  # their measured velocity (n,) rad/s
        # the velocity commands sent (time s of the inputs' clock, (n,) rad/s), oldest first
        self._sent: list[tuple[float, np.ndarray]] = []

    # ------------------------------------------------------------------ helpers
    @property
    def gripper(self) -> GripperCommand:
        """The gripper command currently held."""
        return self._gripper

    def _zeros(self) -> np.ndarray:
        return np.zeros(len(self.params.joint_names))

    def observe(self, now: float, stamp: float, velocity: np.ndarray | None = None) -> None:
        """This tick's time ``now`` and the ``stamp`` of the joint states it sees (s, the
        inputs' clock), and their measured ``velocity`` (n,) rad/s: how old they are, and where
        the commands sent since then have taken the arm."""
        self._input_time = (float(now), float(stamp))
        self.input_age = max(float(now) - float(stamp), 0.0)
        self._seen_velocity = self._zeros() if velocity is None else \
            np.asarray(velocity, dtype=float)

    def sent(self, now: float, velocities: np.ndarray) -> None:
        """The joint velocities (n,) rad/s the controller sent at ``now`` (s): a velocity driver
        runs each until the next (or its ``driver_command_timeout``). Kept for 2 s."""
        self._sent.append((float(now), np.array(velocities, dtype=float)))
        while len(self._sent) > 1 and self._sent[1][0] < now - 2.0:
            self._sent.pop(0)

    def _commands_since(self, stamp: float, now: float) -> list[tuple[float, np.ndarray]]:
        """The joint velocities (n,) rad/s in force from ``stamp`` to ``now`` (s), as
        (duration s, velocities) pieces: each command sent runs until the next one or the
        driver's ``driver_command_timeout``, then zero."""
        timeout = self.params.driver_command_timeout
        pieces, cursor, zeros = [], stamp, self._zeros()
        for i, (t, v) in enumerate(self._sent):
            nxt = self._sent[i + 1][0] if i + 1 < len(self._sent) else now
            lo, hi = max(t, stamp), min(nxt, now)
            if hi <= lo:
                continue
            if lo > cursor:
                pieces.append((lo - cursor, zeros))
            off = min(max(t + timeout, lo), hi)
            pieces += [(off - lo, v), (hi - off, zeros)]
            cursor = hi
        if now > cursor:
            pieces.append((now - cursor, zeros))
        return [(d, v) for d, v in pieces if d > 0]

    def _arm_now(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Where the arm is now and how fast it moves, ((n,) rad, (n,) rad/s): the joint states
        seen (``q``, measured ``input_age`` s ago, and their velocity) carried forward by the
        commands sent since, through the arm's first-order response (``driver_velocity_lag``).
        A command the driver missed leaves the arm behind this: never nearer to a goal."""
        now, stamp = self._input_time
        tau = self.params.driver_velocity_lag
        q, vel = np.array(q, dtype=float), self._seen_velocity
        if vel.shape != q.shape:
            vel = self._zeros()
        for d, u in self._commands_since(stamp, now):
            if tau > 0:
                decay = math.exp(-d / tau)
                q = q + u * d + (vel - u) * tau * (1.0 - decay)
                vel = u + (vel - u) * decay
            else:
                q, vel = q + u * d, u
        return q, vel

    def _track(self, q: np.ndarray, q_target: np.ndarray) -> tuple[np.ndarray, bool]:
        """Proportional joint-space tracking, scaled so the velocity direction is kept.

        The gain is at most 1 / (joint-state age + ``driver_command_timeout`` +
        ``driver_velocity_lag``): a command that runs for that whole time ends at the target,
        not beyond it (old joint states, late ticks)."""
        err = q_target - q
        horizon = self.input_age + self.params.driver_command_timeout + \
            self.params.driver_velocity_lag
        v = min(self.params.ik_gain, 1.0 / max(horizon, 1e-6)) * err
        vmax = np.asarray(self.params.max_joint_velocity)
        scale = float(np.max(np.abs(v) / vmax))
        if scale > 1.0:
            v = v / scale
        return v, bool(np.max(np.abs(err)) < self.params.joint_tolerance)

    def _start_line(self, t: float, q: np.ndarray, p1: np.ndarray) -> None:
        assert self.kinematics is not None
        p0 = self.kinematics.tool_position(q)
        duration = float(np.linalg.norm(p1 - p0)) / self.params.cartesian_speed
        self._line = (p0, np.asarray(p1, dtype=float), t, max(duration, 1e-3))
        self._t0 = t

    def _follow_line(self, t: float, q: np.ndarray) -> tuple[np.ndarray, bool, bool]:
        """Track the straight tool segment; returns (velocities, done, failed)."""
        assert self._line is not None and self.kinematics is not None
        p0, p1, t0, duration = self._line
        s = min(1.0, (t - t0) / duration)
        setpoint = p0 + (p1 - p0) * s
        q_set = self.kinematics.grasp_ik(setpoint, self._yaw, q, self._tilt,
                                         turn_round=self._tilt == 0.0)
        for tilt in (t for t in self._tilt_steps() if t > self._tilt and q_set is None):
            # no pose on the way at this lean: lean further rather than give up (seed 1
            # trial 60: the Panda's elbow at its limit half way down to a near cylinder)
            q_set = self.kinematics.grasp_ik(setpoint, self._yaw, q, tilt, turn_round=False)
            self._tilt = tilt if q_set is not None else self._tilt
        if q_set is None:
            return self._zeros(), False, True
        v, reached = self._track(q, q_set)
        v = self._bound_to_goal(q, v, p1)
        if s >= 1.0:
            close = float(np.linalg.norm(self.kinematics.tool_position(q) - p1)) < 0.004
            if reached or close:
                return v, True, False
        if t - t0 > duration + self.params.segment_timeout:
            return self._zeros(), False, True
        return v, False, False

    def _bound_to_goal(self, q: np.ndarray, v: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Joint velocities ``v`` (n,) rad/s scaled down so that the command cannot carry the
        tool past ``goal`` (3,) m, the end of its segment (the table, at the end of the
        descent), however late the next tick and however old the joint states ``q`` (n,) rad.

        From where the arm is now (:meth:`_arm_now`: the joint states seen carried forward by
        the commands sent since), a command ``u`` that the driver runs for its
        ``driver_command_timeout`` T (no newer one: a late tick) and the arm's response lag tau
        move the joints ``u T + v_now tau`` in all: the tool speed of ``u`` is at most
        ``(left - tau |v_now|) / T``. Far from the goal nothing changes; over the last
        ``cartesian_speed * T`` (3 cm) the tool slows down (time constant T, 0.25 s)."""
        assert self.kinematics is not None
        q_now, v_now = self._arm_now(q)
        tool = self.kinematics.tool_position(q_now)
        left = float(np.linalg.norm(np.asarray(goal, dtype=float) - tool))

        def tool_speed(joint_velocity: np.ndarray) -> float:
            # by a small step of the forward kinematics (no Jacobian needed from the model)
            step = 1e-3
            moved = self.kinematics.tool_position(q_now + joint_velocity * step) - tool
            return float(np.linalg.norm(moved)) / step

        coast = self.params.driver_velocity_lag * tool_speed(v_now)
        limit = max(left - coast, 0.0) / max(self.params.driver_command_timeout, 1e-3)
        speed = tool_speed(v)
        return v * (limit / speed) if speed > limit else v

    def _height(self) -> float:
        """Object height (m): measured from above when available, else the shape's size."""
        if self.object_height is not None:
            return self.object_height
        return self.params.shape_value(self.shape, 'size')

    def _grasp_z(self) -> float:
        """Grasp-point height (m): a fraction of the object height, but high enough that the
        fingertips, which reach ``min_tcp_height`` below the grasp point, clear the table."""
        frac = self.params.shape_value(self.shape, 'grasp_height_fraction')
        offset = self.params.shape_value(self.shape, 'grasp_height_offset')
        return self.params.table_height + max(self._height() * frac + offset,
                                              self.params.min_tcp_height)

    def _grasp_point(self) -> np.ndarray:
        """Where the straight descent ends (m, base frame): above the object's centre at
        :meth:`_grasp_z`."""
        assert self.object_position is not None
        target = self.object_position.copy()
        target[2] = self._grasp_z()
        return target

    def _pregrasp_point(self) -> np.ndarray:
        assert self.object_position is not None
        top = self.params.table_height + self._height()
        p = self.object_position.copy()
        p[2] = top + self.params.shape_value(self.shape, 'approach_height')
        return p

    def _measure(self, q: np.ndarray, vision: VisionFrame | None,
                 camera: CameraModel | None) -> np.ndarray | None:
        if vision is None or vision.object_of_interest is None or camera is None:
            return None
        assert self.kinematics is not None
        obs = vision.object_of_interest
        if obs.shape in ('cube', 'cylinder', 'sphere'):
            self.shape = obs.shape     # the depth CNN classifies while the arm holds still
        if (camera.width, camera.height) != (vision.image_width, vision.image_height):
            camera = camera.scaled_to(vision.image_width, vision.image_height)
        cam_pos, cam_rot = self.kinematics.camera_pose(q)
        size = self._height()
        centre, surface = estimate_object_position(
            (obs.centre_x, obs.centre_y), obs.distance, obs.bbox[2], camera, cam_pos, cam_rot,
            size, self.params.table_height)
        if cam_rot[2, 2] < -0.95:
            # looking straight down: the median depth is the top face (a sphere's cap a little
            # lower); keep a plausible height of a table-top object
            height = float(surface[2]) - self.params.table_height
            self.object_height = min(max(height, 0.02), 0.2)
            centre[2] = self.params.table_height + self.object_height / 2
        return centre

    def _measure_frames(self, q: np.ndarray, vision: VisionFrame | None,
                        camera: CameraModel | None) -> np.ndarray | bool | None:
        """The median of ``measure_frames`` measurements from distinct camera frames (a noisy
        depth camera and detection scatter from frame to frame); False while collecting, None
        when the object is not in view."""
        estimate = self._measure(q, vision, camera)
        if estimate is None:
            self._samples = []
            return None
        assert vision is not None
        if not self._samples or self._samples[-1][0] != vision.stamp:
            self._samples.append((vision.stamp, estimate, self.object_height))
        if len(self._samples) < max(1, self.params.measure_frames):
            return False
        centres = np.array([s[1] for s in self._samples])
        heights = [s[2] for s in self._samples if s[2] is not None]
        self._samples = []
        if heights:
            self.object_height = float(np.median(heights))
        return np.median(centres, axis=0)

    def _plan_pregrasp(self, q: np.ndarray) -> str:
        """Set the joint target above the object; returns '' or why it is not reachable."""
        assert self.object_position is not None and self.kinematics is not None
        x, y = float(self.object_position[0]), float(self.object_position[1])
        reach = math.hypot(x, y)
        if not self.params.min_reach <= reach <= self.params.max_reach:
            return (f'object at {reach:.2f} m from the base axis is outside the reach '
                    f'{self.params.min_reach:.2f}-{self.params.max_reach:.2f} m')
        # fingers close across the radial direction, turned by the shape's wrist yaw
        # thumb towards the base (pi): the natural hand orientation of this arm (joint 6 near 0)
        self._yaw = wrap_angle(math.atan2(y, x) + math.pi
                               + self.params.shape_value(self.shape, 'wrist_yaw'))
        for tilt, hand_yaw in self._leans(self._yaw):
            # every lean at yaw before the hand turned round (the same grasp): turned round,
            # the Panda found poses twisted about joint 1 that hit its own base (seed 1 trial
            # 55, vertical); the six-joint arms need neither in the scenes' range
            q_pre = self.kinematics.grasp_ik(self._pregrasp_point(), hand_yaw, q, tilt,
                                             turn_round=False)
            # and the descent's end at the same lean (seed 1 trials 55, 60, 80: a near
            # cylinder had a pose above it but none at the grasp height, the descent failed)
            if q_pre is not None and self.kinematics.grasp_ik(
                    self._grasp_point(), hand_yaw, q_pre, tilt, turn_round=False) is not None:
                self._q_target, self._tilt, self._yaw = q_pre, tilt, hand_yaw
                return ''
        return f'no inverse-kinematics solution above the object at ({x:.2f}, {y:.2f}) m'

    def reachable(self, position: np.ndarray, shape: str, q: np.ndarray) -> str:
        """Whether an object of ``shape`` at ``position`` (3,) m has a pre-grasp and a grasp
        pose from joints ``q`` (n,) rad, as the approach plans them: '' or why not (the
        reachability map of ``mindgrasp robot check``). Leaves the policy's plan unchanged."""
        saved = (self.object_position, self.object_height, self.shape, self._q_target,
                 self._tilt, self._yaw)
        self.object_position, self.object_height = np.asarray(position, dtype=float), None
        self.shape = shape
        try:
            return self._plan_pregrasp(np.asarray(q, dtype=float))
        finally:
            (self.object_position, self.object_height, self.shape, self._q_target, self._tilt,
             self._yaw) = saved

    def _leans(self, yaw: float) -> list[tuple[float, float]]:
        """(tool lean rad, yaw rad) to try for the pre-grasp, in order: vertical, then leaning
        in steps of about 0.15 rad up to ``max_approach_tilt``, at ``yaw``, then the same at
        ``yaw + pi``: the least lean that has an IK solution."""
        return [(t, y) for y in (yaw, wrap_angle(yaw + math.pi))
                for t in [0.0, *self._tilt_steps()]]

    def _tilt_steps(self) -> list[float]:
        """The tool leans (rad) other than vertical, ascending: steps of about 0.15 rad up to
        ``max_approach_tilt`` (none when it is 0)."""
        steps = math.ceil(self.params.max_approach_tilt / 0.15 - 1e-9)
        return [self.params.max_approach_tilt * i / steps for i in range(1, steps + 1)]

    # ------------------------------------------------------------------ state 4
    def begin_approach(self, t: float, shape: str, attempt: int) -> None:
        """Enter the final approach: open the hand, then measure."""
        self.shape = shape if shape in ('cube', 'cylinder', 'sphere') else 'unknown'
        self.attempt = attempt
        self.phase = 'open'
        self._t0 = t
        self._refinements = 0
        self._tilt = 0.0
        self.object_height = None
        self._lost_since = None
        self._samples = []
        self._gripper = GripperCommand(self.params.gripper_open_position,
                                       self.params.shape_value(self.shape, 'close_force'))

    def approach_step(self, t: float, q: np.ndarray, vision: VisionFrame | None,
                      camera: CameraModel | None, gripper: GripperState | None) -> PolicyStep:
        """One tick of the final approach; event ``at_grasp_pose`` or ``abort``."""
        p = self.params
        if self.kinematics is None:
            return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort',
                              'no arm kinematics model is configured for the final approach')
        if self.phase == 'open':
            opened = gripper is None or gripper.opening > 0.9
            if (t - self._t0 >= p.settle_time and opened) or t - self._t0 > p.close_timeout:
                self.phase = 'measure'
                self._t0 = t
            return PolicyStep(self._zeros(), self._gripper, 'open')
        if self.phase in ('measure', 'refine'):
            if t - self._t0 < p.settle_time:
                return PolicyStep(self._zeros(), self._gripper, self.phase)
            estimate = self._measure_frames(q, vision, camera)
            if estimate is False:
                return PolicyStep(self._zeros(), self._gripper, self.phase)   # more frames
            if estimate is None:
                if self.phase == 'refine':   # lost from above: keep the first estimate
                    return self._begin_descend(t, q)
                self._lost_since = self._lost_since if self._lost_since is not None else t
                if t - self._lost_since > p.object_lost_timeout:
                    return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort',
                                      'object of interest not visible for the final approach')
                return PolicyStep(self._zeros(), self._gripper, self.phase)
            if self.phase == 'measure':
                self.object_position = estimate
            else:
                assert self.object_position is not None
                shift = float(np.linalg.norm(estimate[:2] - self.object_position[:2]))
                if shift > p.refine_max_correction:
                    return self._begin_descend(t, q)   # implausible jump: another object
                self.object_position = estimate
                self._refinements += 1
                if shift < 0.004 or self._refinements >= p.max_refinements:
                    return self._begin_descend(t, q)
            why = self._plan_pregrasp(q)
            if why:
                return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort', why)
            self.phase = 'to_pregrasp'
            self._t0 = t
            return PolicyStep(self._zeros(), self._gripper, self.phase)
        if self.phase == 'to_pregrasp':
            assert self._q_target is not None
            v, reached = self._track(q, self._q_target)
            if reached:
                self.phase = 'refine'
                self._t0 = t
                return PolicyStep(self._zeros(), self._gripper, self.phase)
            if t - self._t0 > p.segment_timeout:
                return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort',
                                  f'pre-grasp pose not reached in {p.segment_timeout:.1f} s')
            return PolicyStep(v, self._gripper, self.phase)
        if self.phase == 'descend':
            v, done, failed = self._follow_line(t, q)
            if failed:
                return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort',
                                  'the straight descent to the grasp height failed (IK)')
            if done:
                return PolicyStep(self._zeros(), self._gripper, self.phase, 'at_grasp_pose',
                                  f'gripper at the grasp height of the {self.shape}')
            return PolicyStep(v, self._gripper, self.phase)
        return PolicyStep(self._zeros(), self._gripper, self.phase, 'abort',
                          f'unknown approach phase {self.phase!r}')

    def _begin_descend(self, t: float, q: np.ndarray) -> PolicyStep:
        self.phase = 'descend'
        self._start_line(t, q, self._grasp_point())
        return PolicyStep(self._zeros(), self._gripper, self.phase)

    # ------------------------------------------------------------------ straight lift (state 6)
    def start_lift(self, t: float, q: np.ndarray, target: np.ndarray) -> None:
        """Begin a straight tool motion to ``target`` (m) keeping the grasp orientation."""
        self._start_line(t, q, target)

    def lift_step(self, t: float, q: np.ndarray) -> tuple[np.ndarray, bool]:
        """One tick of :meth:`start_lift`; returns (velocities, done)."""
        v, done, failed = self._follow_line(t, q)
        return (self._zeros(), True) if failed else (v, done)

    # ------------------------------------------------------------------ state 5
    def begin_grasp(self, t: float) -> None:
        """Enter the grasp: close with the shape's force limit."""
        self.phase = 'close'
        self._t0 = t
        self._stall_since = None
        self._last_opening = None
        self._contact_since = None
        self._hold_since = None
        self._opening_at_close = None
        self._gripper = GripperCommand(self.params.gripper_closed_position,
                                       self.params.shape_value(self.shape, 'close_force'))

    def _set_hold(self, gripper: GripperState) -> None:
        """Force control of a torque-limited hand: command the fingers ``grip_squeeze`` past
        where they touch the object, so the grip is a stiff position equilibrium. Closing on with
        full torque lets the stronger thumb push the object out between the two fingers."""
        p = self.params
        if p.grip_squeeze <= 0 or p.grasp_check == 'width':
            # jaws keep the full closing command: were they held just past the contact, an
            # object slipping out would leave them apart, and the width check would not see it
            return
        closure = min((1.0 - gripper.opening) + p.grip_squeeze, p.gripper_closed_position)
        self._gripper = GripperCommand(closure, self._gripper.max_force)

    def _holding(self, gripper: GripperState | None,
                 min_fingers: int | None = None) -> tuple[bool, str]:
        """Whether the hand holds something: ``min_fingers`` (default
        ``min_fingers_in_contact``) fingers loaded, and why."""
        wanted = self.params.min_fingers_in_contact if min_fingers is None else min_fingers
        if gripper is None:
            return True, 'no gripper feedback: grasp not verified'
        if gripper.opening <= self.params.closed_empty_opening:
            return False, f'fingers closed on nothing (opening {gripper.opening:.2f})'
        if self.params.grasp_check == 'width':
            return True, f'jaws stopped apart (opening {gripper.opening:.2f})'
        loaded = fingers_loaded(gripper, self.params.finger_contact_effort)
        if loaded is not None:
            # effort sensing: what a real hand knows (contact flags cannot tell the table apart)
            efforts = ', '.join(f'{abs(e):.2f}' for e in gripper.efforts or ())
            if loaded < wanted:
                return False, (f'{loaded} finger(s) push on something (efforts {efforts} N m), '
                               f'{wanted} wanted')
            return True, f'{loaded} fingers loaded (efforts {efforts} N m, opening ' \
                         f'{gripper.opening:.2f})'
        touching = (gripper.contact if gripper.contact is not None
                    else gripper.force >= self.params.contact_min_force)
        if not touching:
            return False, f'no finger contact (force {gripper.force:.1f} N)'
        n = gripper.fingers_in_contact
        if n is not None and n < wanted:
            return False, f'only {n} finger(s) touch the object, {wanted} wanted'
        fingers = '' if n is None else f'{n} fingers, '
        return True, f'finger contact ({fingers}opening {gripper.opening:.2f})'

    def _fail(self, t: float, q: np.ndarray, why: str, can_retry: bool) -> PolicyStep:
        """Open, back off upwards, then report retry or failure."""
        assert self.kinematics is not None
        self._gripper = GripperCommand(self.params.gripper_open_position, self._gripper.max_force)
        self._after_retreat = 'retry' if can_retry else 'failed'
        self._retreat_reason = why
        tool = self.kinematics.tool_position(q)
        target = tool.copy()
        target[2] = max(tool[2], self._grasp_z() + self.params.shape_value(self.shape,
                                                                            'approach_height'))
        self.phase = 'retreat'
        self._start_line(t, q, target)
        return PolicyStep(self._zeros(), self._gripper, self.phase)

    def _fingers_stalled(self, t: float, gripper: GripperState) -> bool:
        """True once the closing fingers have not moved for ``FINGER_STALL_TIME`` (s of the active
        clock ``t``).

        A gripper state already read, and older than half that window, says nothing more about
        the fingers: the driver is late. On a loaded machine the simulator stalled 0.3 s, the
        controller read its last open state again and again as fingers that had stopped, and
        the grasp failed with the hand round the cube (efforts 0.01 N m). A state read again
        while younger counts as before (lock-step ticks do that between the simulator's
        states), which keeps lock-step records as they were."""
        last = self._last_opening
        if last is not None and gripper.stamp <= last[1] \
                and self._input_time[0] - gripper.stamp > FINGER_STALL_TIME / 2:
            return False
        self._last_opening = (t, gripper.stamp, gripper.opening)
        if last is not None:
            rate = abs(gripper.opening - last[2]) / max(t - last[0], 1e-3)
            if rate < self.params.stall_rate:
                self._stall_since = self._stall_since if self._stall_since is not None else t
                return t - self._stall_since >= FINGER_STALL_TIME
        self._stall_since = None
        return False

    def grasp_step(self, t: float, q: np.ndarray, gripper: GripperState | None) -> PolicyStep:
        """One tick of the grasp; events ``grasped``, ``retry`` or ``failed``."""
        p = self.params
        can_retry = self.attempt < p.grasp_retries
        if self.kinematics is None:
            return PolicyStep(self._zeros(), self._gripper, self.phase, 'failed',
                              'no arm kinematics model is configured for the grasp')
        if self.phase == 'close':
            elapsed = t - self._t0
            stalled = False
            if gripper is not None:
                if self._opening_at_close is None:
                    self._opening_at_close = gripper.opening
                stalled = self._fingers_stalled(t, gripper)
                n = fingers_loaded(gripper, p.finger_contact_effort)
                if n is None:
                    n = gripper.fingers_in_contact
                if p.grasp_check == 'width':
                    n = None     # jaws: closing ends when they stall (on the object or shut)
                if self._opening_at_close - gripper.opening < p.contact_min_travel:
                    # a load before the fingers closed is not the object's: open fingertips
                    # pressed on the table (a live arm that went a few mm low on a busy machine
                    # held open at the contact point and lifted nothing)
                    n = None
                if self._hold_since is None and n is not None and n >= p.min_fingers_in_contact:
                    # every finger touches: stop closing and hold a little past this point
                    self._contact_since = self._contact_since if self._contact_since is not None \
                        else t
                    if t - self._contact_since >= p.contact_settle_time:
                        self._set_hold(gripper)
                        self._hold_since = t
            held_long = self._hold_since is not None and t - self._hold_since >= p.settle_time
            if (elapsed >= 0.3 and stalled) or held_long or elapsed >= p.close_timeout:
                ok, why = self._holding(gripper)
                if not ok:
                    return self._fail(t, q, why, can_retry)
                if self._hold_since is None and gripper is not None:
                    self._set_hold(gripper)
                tool = self.kinematics.tool_position(q)
                self.phase = 'lift'
                self._start_line(t, q, tool + np.array([0.0, 0.0, p.lift_height]))
            return PolicyStep(self._zeros(), self._gripper, 'close')
        if self.phase == 'lift':
            v, done, failed = self._follow_line(t, q)
            if done or failed:
                self.phase = 'check_lift'
                self._t0 = t
                return PolicyStep(self._zeros(), self._gripper, self.phase)
            return PolicyStep(v, self._gripper, self.phase)
        if self.phase == 'check_lift':
            if t - self._t0 < p.lift_check_time:
                return PolicyStep(self._zeros(), self._gripper, self.phase)
            ok, why = self._holding(gripper, p.min_fingers_holding)
            if not ok:
                return self._fail(t, q, f'slipped after the lift: {why}', can_retry)
            self.phase = 'hold'
            self._t0 = t
            self._retreat_reason = why
            return PolicyStep(self._zeros(), self._gripper, self.phase)
        if self.phase == 'hold':
            if t - self._t0 >= p.grasp_hold_time:
                return PolicyStep(self._zeros(), self._gripper, self.phase, 'grasped',
                                  f'{self.shape} grasped and lifted ({self._retreat_reason})')
            return PolicyStep(self._zeros(), self._gripper, self.phase)
        if self.phase == 'retreat':
            v, done, failed = self._follow_line(t, q)
            if done or failed:
                return PolicyStep(self._zeros(), self._gripper, self.phase, self._after_retreat,
                                  self._retreat_reason)
            return PolicyStep(v, self._gripper, self.phase)
        return PolicyStep(self._zeros(), self._gripper, self.phase, 'failed',
                          f'unknown grasp phase {self.phase!r}')
