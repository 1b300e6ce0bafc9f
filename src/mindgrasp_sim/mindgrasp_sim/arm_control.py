"""Arm and gripper control of the simulation, and the readings of the arm's joints and hand.

Joint control follows a ros2_control forward velocity controller on a position-controlled arm:
each physics step integrates the commanded (clipped) velocity into a joint reference that a stiff,
torque-limited PD motor tracks (:meth:`ArmControlMixin.step`), with the realism profile's
controller lag and a velocity governor. :class:`~mindgrasp_sim.simulation.Simulation` inherits
these methods; the attributes they use are set by its constructor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mindgrasp_sim.control import validate_velocities
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.pybullet_quiet import BulletClient, pb
from mindgrasp_sim.realism import Realism

#: PD motor position gain (pybullet's per-step error fraction): stiff, so gravity sag < 1 mrad
ARM_POSITION_GAIN = 0.8
_GOVERNOR_TOLERANCE = 1.05


@dataclass
class _Robot:
    body: int
    q_ref: np.ndarray
    # the velocity command and the velocity the motors follow after the lag (n_joints,) rad/s,
    # set through command() and apply(), which note whether they are non-zero: the physics loop
    # asks at every step, and ndarray.any() there cost more than the rest of an idle step
    v_cmd: np.ndarray
    v_applied: np.ndarray
    closure: float = 0.0
    gripper_dirty: bool = True
    holding: bool = False     # zero command already given to the motors: nothing to update
    cmd_moving: bool = False
    applied_moving: bool = False
    # getJointStates of the arm and the physics step it was read after: the tracker, the
    # governor and every published reading want the same states in a step (one call, not 4)
    states: tuple = ()
    states_step: int = -1

    def command(self, v: np.ndarray) -> None:
        self.v_cmd = v
        self.cmd_moving = bool(v.any())

    def apply(self, v: np.ndarray) -> None:
        self.v_applied = v
        self.applied_moving = bool(v.any())


class ArmControlMixin:
    """Velocity and gripper commands, the physics step, and the joint and hand readings of
    :class:`~mindgrasp_sim.simulation.Simulation` (arrays (n_joints,) in rad, rad/s, N m;
    fingers (n_fingers,) rad)."""

    # set by Simulation.__init__ (joint indices are PyBullet's; limits (n_joints,) rad, rad/s, N m)
    _p: BulletClient
    _robots: dict[str, _Robot]
    _arm_idx: list[int]
    _finger_idx: list[int]
    _finger_driven: list[tuple[int, int]]
    _finger_links: dict[int, str]
    _finger_open: np.ndarray
    _finger_closed: np.ndarray
    _finger_effort: list[float]
    _finger_velocity: list[float]
    _arm_position_gains: tuple[float, ...]
    _arm_velocity_gains: tuple[float, ...]
    _lag_scale: float
    _step_count: int
    realism: Realism
    n_joints: int
    dt: float
    lower: np.ndarray
    upper: np.ndarray
    max_velocity: np.ndarray
    max_effort: np.ndarray
    finger_names: tuple[str, ...]

    def set_joint_velocities(self, velocities: np.ndarray, robot: str = 'user') -> None:
        """Command joint velocities (n_joints,) rad/s, clipped to the joint velocity limits.

        Raises SimError for a wrong length or NaN/inf (the previous command stays in force).
        """
        v = validate_velocities(velocities, self.n_joints)
        r = self._robot(robot)
        r.command(np.clip(v, -self.max_velocity, self.max_velocity))
        r.holding = False

    def stop(self, robot: str = 'user') -> None:
        """Zero velocity command (the arm holds its current reference)."""
        self._robot(robot).command(np.zeros(self.n_joints))

    def set_gripper(self, closure: float, robot: str = 'user') -> None:
        """Gripper target: 0 open .. 1 closed; fingers close with limited torque (they stop on
        the object and squeeze it with the joint effort limit)."""
        c = float(closure)
        if not math.isfinite(c):
            msg = f'Gripper closure must be a finite number in [0, 1], got {closure!r}.'
            raise SimError(msg)
        r = self._robot(robot)
        r.closure = min(max(c, 0.0), 1.0)
        r.gripper_dirty = True

    def set_joint_positions(self, positions: np.ndarray, robot: str = 'user') -> None:
        """Teleport the arm to joint positions (n_joints,) rad (tests, scripted set-ups; not
        physical)."""
        q = np.clip(np.asarray(positions, dtype=float).reshape(self.n_joints), self.lower,
                    self.upper)
        r = self._robot(robot)
        for i, j in enumerate(self._arm_idx):
            self._reset_arm_joint(r, j, q[i], 0.0)
        r.q_ref = q.copy()
        r.command(np.zeros(self.n_joints))
        r.apply(np.zeros(self.n_joints))
        r.holding = False

    def step(self, n: int = 1) -> None:
        """Advance the physics by ``n`` steps of ``1 / physics_hz`` s."""
        p = self._p
        dt = self.dt
        lag = self.realism.profile.joints.lag > 0
        for _ in range(int(n)):
            for name, r in self._robots.items():
                lagging = lag and name == 'user'     # the training robot is a drawn prompt
                if lagging and (r.cmd_moving or r.applied_moving):
                    # a real velocity controller follows the command with a lag
                    v = self.realism.lagged_velocity(r.v_applied, r.v_cmd, dt)
                    if not r.cmd_moving and np.max(np.abs(v)) < 1e-4:
                        v = np.zeros(self.n_joints)
                    r.apply(v)
                    r.holding = False
                elif not lagging and r.v_applied is not r.v_cmd:
                    r.v_applied, r.applied_moving = r.v_cmd, r.cmd_moving
                if r.applied_moving:
                    self._track(p, r, dt)
                elif not r.holding:
                    # stopping: hold the current reference (set once, then left alone), no
                    # further ahead of the joints than one step at the velocity limit: a lagging
                    # arm must not be pulled there faster than its limit
                    q = np.array([st[0] for st in self._arm_states(r)])
                    reach = self.max_velocity * self._lag_scale
                    r.q_ref = np.minimum(np.maximum(r.q_ref, q - reach), q + reach)
                    p.setJointMotorControlArray(
                        r.body, self._arm_idx, pb.POSITION_CONTROL, targetPositions=r.q_ref,
                        targetVelocities=[0.0] * self.n_joints,
                        forces=self.max_effort, positionGains=self._arm_position_gains,
                        velocityGains=self._arm_velocity_gains)
                    r.holding = True
                if r.gripper_dirty:
                    target = self._finger_open + (self._finger_closed - self._finger_open) \
                        * r.closure
                    for k, j in self._finger_driven:
                        p.setJointMotorControl2(
                            r.body, j, pb.POSITION_CONTROL, targetPosition=float(target[k]),
                            force=self._finger_effort[k], maxVelocity=self._finger_velocity[k],
                            positionGain=0.05, velocityGain=1.0)
                    r.gripper_dirty = False
            p.stepSimulation()
            self._step_count += 1
            for r in self._robots.values():
                if r.applied_moving:
                    self._govern(p, r)

    def _track(self, p: BulletClient, r: _Robot, dt: float) -> None:
        """Advance the joint reference by the velocity command and send it to the motors.

        PyBullet's position motor aims at the joint velocity ``v_ff + Kp (target - q) / dt``
        (Kp the position gain, velocity gain 1). Aiming at the advanced reference added the step
        ``v dt`` twice (1.8 v at the first step, 2.0-2.9 rad/s against URDF limits of 1.0-1.6);
        so the target is the reference at the start of the step, with the correction of any
        lag bounded so that the aim stays within the joint's velocity limit.
        """
        q = np.array([s[0] for s in self._arm_states(r)])
        # keep the reference near the real joints (a blocked arm does not wind up); ufuncs
        # rather than np.clip, whose wrapper costs more than the arithmetic at 240 Hz
        q_ref = np.minimum(np.maximum(r.q_ref, q - 0.05), q + 0.05)
        new_ref = np.minimum(np.maximum(q_ref + r.v_applied * dt, self.lower), self.upper)
        v_ff = (new_ref - q_ref) / dt
        r.q_ref = new_ref
        vmax = self.max_velocity
        lag = np.minimum(np.maximum(q_ref - q, (-vmax - v_ff) * self._lag_scale),
                         (vmax - v_ff) * self._lag_scale)
        p.setJointMotorControlArray(
            r.body, self._arm_idx, pb.POSITION_CONTROL, targetPositions=q + lag,
            targetVelocities=v_ff, forces=self.max_effort,
            positionGains=self._arm_position_gains, velocityGains=self._arm_velocity_gains)

    def _reset_arm_joint(self, r: _Robot, joint: int, q: float, v: float) -> None:
        """Set arm joint ``joint`` (PyBullet index) of ``r`` to ``q`` rad, ``v`` rad/s; the
        cached joint states of this step are stale after it."""
        self._p.resetJointState(r.body, joint, q, v)
        r.states_step = -1

    def _arm_states(self, r: _Robot) -> tuple:
        """``getJointStates`` of the arm's joints after the latest physics step (read once per
        step; a teleport or a governor reset reads them again)."""
        if r.states_step != self._step_count:
            r.states = self._p.getJointStates(r.body, self._arm_idx)
            r.states_step = self._step_count
        return r.states

    def _govern(self, p: BulletClient, r: _Robot) -> None:
        """The drive's velocity governor: a joint more than 5 % faster than its URDF limit after
        a step (the constraint solver's 50 iterations leave up to ~10 % where joints couple) is
        slowed to the limit, so that measured velocities stay within 5 % of it."""
        v = np.array([st[1] for st in self._arm_states(r)])
        # the tolerance: resetting a joint's state disturbs the contacts of a held object (a
        # small sphere slips), so the governor acts on the solver's gross errors only, not on
        # the few per cent a joint reads above its limit as a motion starts
        over = np.abs(v) > self.max_velocity * _GOVERNOR_TOLERANCE
        if over.any():
            for i in np.flatnonzero(over):
                j = self._arm_idx[i]
                q = p.getJointState(r.body, j)[0]
                self._reset_arm_joint(r, j, q, float(np.sign(v[i]) * self.max_velocity[i]))

    def joint_positions(self, robot: str = 'user') -> np.ndarray:
        """Arm joint positions (n_joints,) rad."""
        r = self._robot(robot)
        return np.array([s[0] for s in self._arm_states(r)])

    def joint_velocities(self, robot: str = 'user') -> np.ndarray:
        """Arm joint velocities (n_joints,) rad/s."""
        r = self._robot(robot)
        return np.array([s[1] for s in self._arm_states(r)])

    def joint_readings(self, robot: str = 'user') -> tuple[np.ndarray, np.ndarray]:
        """What the arm's encoders report: joint positions (n,) rad and velocities (n,) rad/s,
        with the realism profile's encoder noise and offsets (exact without realism)."""
        q, v = self.joint_positions(robot), self.joint_velocities(robot)
        if robot != 'user':
            return q, v     # the training robot is a prompt on screen, not a sensed arm
        return self.realism.joint_readings(q, v)

    def joint_efforts(self, robot: str = 'user') -> np.ndarray:
        """Arm joint motor torques (n_joints,) N m applied in the last step."""
        r = self._robot(robot)
        return np.array([s[3] for s in self._arm_states(r)])

    def finger_positions(self, robot: str = 'user') -> np.ndarray:
        """Finger joint angles (3,) rad (thumb, left, right); larger is more closed."""
        r = self._robot(robot)
        return np.array([s[0] for s in self._p.getJointStates(r.body, self._finger_idx)])

    def commanded_velocities(self, robot: str = 'user') -> np.ndarray:
        """The velocity command in force (n_joints,) rad/s, after clipping."""
        return self._robot(robot).v_cmd.copy()

    def gripper_state(self, robot: str = 'user') -> dict:
        """Gripper state as the hand senses it: ``closure`` (commanded, 0..1), ``positions``
        (3,) rad, ``efforts`` (3,) N m (finger motor torques), ``contacts`` (3,) bool, ``names``
        (thumb, left, right).

        A contact flag means "the finger touches a scene object" without realism; with the
        realism contact mode ``any`` it means "touches any surface" (the table too), as a real
        tactile sensor reports it.
        """
        r = self._robot(robot)
        if self.realism.profile.contacts.mode == 'any':
            touched = {c[3] for c in self._p.getContactPoints(bodyA=r.body)
                       if c[2] != r.body and c[3] in self._finger_links}
            contacts = [j in touched for j in self._finger_idx]
        else:
            touching = self._finger_contacts(r.body)
            contacts = [any(j in fingers for fingers in touching.values())
                        for j in self._finger_idx]
        efforts = np.array([s[3] for s in self._p.getJointStates(r.body, self._finger_idx)])
        if robot == 'user':
            efforts = self.realism.finger_efforts(efforts)
        return {'closure': r.closure, 'positions': self.finger_positions(robot),
                'efforts': efforts, 'contacts': np.array(contacts, dtype=bool),
                'names': self.finger_names}
