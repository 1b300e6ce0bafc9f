"""Kinematics of the simulated arm: link poses in the world, and forward kinematics, the TCP
Jacobian and inverse kinematics on a kinematic twin (a second, never stepped PyBullet client).
:class:`~mindgrasp_sim.simulation.Simulation` inherits these methods; the attributes they use are
set by its constructor."""

from __future__ import annotations

import math

import numpy as np

from mindgrasp_common.robot_description import LinkFrame, RobotDescription
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.pybullet_quiet import BulletClient, pb


class KinematicsMixin:
    """Poses (position (3,) m, quaternion xyzw (4,)), FK, Jacobian and IK (joints (n_joints,)
    rad) of :class:`~mindgrasp_sim.simulation.Simulation`."""

    # set by Simulation.__init__ (PyBullet joint and link indices)
    _p: BulletClient
    _kin: BulletClient
    _kin_body: int
    _arm_idx: list[int]
    _finger_idx: list[int]
    _finger_open: np.ndarray
    _finger_closed: np.ndarray
    _tcp_idx: int
    _cam_idx: int
    _names: dict[str, int]
    robot: RobotDescription
    n_joints: int
    lower: np.ndarray
    upper: np.ndarray
    last_ik_error: float

    def _link_pose(self, body: int, link: int) -> tuple[np.ndarray, np.ndarray]:
        st = self._p.getLinkState(body, link, computeForwardKinematics=True)
        return np.array(st[4]), np.array(st[5])

    def ee_pose(self, robot: str = 'user') -> tuple[np.ndarray, np.ndarray]:
        """Tool centre point (between the fingertips) pose: position (3,) m, quaternion (4,)
        xyzw, world frame."""
        pos, orn = self._link_pose(self._robot(robot).body, self._tcp_idx)
        return _in_link(pos, orn, self.robot.tcp)

    def camera_pose(self, robot: str = 'user') -> tuple[np.ndarray, np.ndarray]:
        """Camera optical frame pose (z forward, x right, y down): position (3,) m, quat xyzw."""
        pos, orn = self._link_pose(self._robot(robot).body, self._cam_idx)
        return _in_link(pos, orn, self.robot.camera)

    def link_pose(self, link: str, robot: str = 'user') -> tuple[np.ndarray, np.ndarray]:
        """Pose of a named link of the robot (the child link of joint ``link`` or link name)."""
        body = self._robot(robot).body
        for j in range(self._p.getNumJoints(body)):
            info = self._p.getJointInfo(body, j)
            if link in (info[1].decode(), info[12].decode()):
                return self._link_pose(body, j)
        msg = f'Unknown link {link!r}; the robot has {sorted(self._names)}.'
        raise SimError(msg)

    def _kin_set(self, q: np.ndarray) -> None:
        for i, j in enumerate(self._arm_idx):
            self._kin.resetJointState(self._kin_body, j, float(q[i]))

    def forward_kinematics(self, q: np.ndarray, link: str = 'tcp'
                           ) -> tuple[np.ndarray, np.ndarray]:
        """Pose (position (3,) m, quaternion xyzw (4,)) of ``link`` ('tcp' or 'camera') for
        joint positions q (n,) rad, computed on a kinematic twin (the simulation is untouched)."""
        self._kin_set(np.asarray(q, dtype=float))
        idx = {'tcp': self._tcp_idx, 'camera': self._cam_idx}.get(link)
        if idx is None:
            msg = f"forward_kinematics link must be 'tcp' or 'camera', got {link!r}."
            raise SimError(msg)
        st = self._kin.getLinkState(self._kin_body, idx, computeForwardKinematics=True)
        pos, orn = np.array(st[4]), np.array(st[5])
        return _in_link(pos, orn, self.robot.camera if link == 'camera' else self.robot.tcp)

    def tool_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Geometric Jacobian (6, n) of the TCP at joints ``q`` (n,) rad, on the kinematic twin:
        rows linear (m/s) and angular (rad/s) velocity in the base frame per rad/s of each arm
        joint (pybullet.calculateJacobian, fingers open)."""
        q = np.asarray(q, dtype=float)
        self._kin_set(q)
        movable = [j for j in range(self._kin.getNumJoints(self._kin_body))
                   if self._kin.getJointInfo(self._kin_body, j)[2] != pb.JOINT_FIXED]
        positions = [float(q[self._arm_idx.index(j)]) if j in self._arm_idx else 0.0
                     for j in movable]
        zeros = [0.0] * len(movable)
        lin, ang = self._kin.calculateJacobian(self._kin_body, self._tcp_idx, [0.0, 0.0, 0.0],
                                               positions, zeros, zeros)
        cols = [movable.index(j) for j in self._arm_idx]
        return np.vstack([np.asarray(lin)[:, cols], np.asarray(ang)[:, cols]])

    def inverse_kinematics(self, target_pos: np.ndarray, target_quat: np.ndarray | None = None,
                           robot: str = 'user', seed_q: np.ndarray | None = None,
                           iterations: int = 30, tolerance: float = 1e-3) -> np.ndarray:
        """Joint positions (n,) rad that put the TCP at ``target_pos`` (3,) m (and orientation
        ``target_quat`` xyzw, if given), within the joint limits.

        Uses pybullet.calculateInverseKinematics (damped least squares, null space towards the
        seed) iterated on a kinematic twin from ``seed_q`` (default: the current joints).
        The result may be approximate when the target is out of reach: ``last_ik_error`` holds
        the residual (m, plus 0.1 m per rad of orientation error); check it, or the pose from
        :meth:`forward_kinematics`.
        """
        target_pos = np.asarray(target_pos, dtype=float).reshape(3)
        if not np.all(np.isfinite(target_pos)):
            msg = f'IK target position must be finite (m), got {target_pos.tolist()}.'
            raise SimError(msg)
        q0 = (self.joint_positions(robot) if seed_q is None
              else np.asarray(seed_q, dtype=float).reshape(self.n_joints)).copy()
        best, best_err = self._ik_from(q0, target_pos, target_quat, iterations, tolerance)
        if best_err > tolerance:
            # damped least squares rarely swings the base far: retry with joint 1 facing the target
            q1 = q0.copy()
            q1[0] = np.clip(math.atan2(target_pos[1], target_pos[0]), self.lower[0], self.upper[0])
            q, err = self._ik_from(q1, target_pos, target_quat, iterations, tolerance)
            if err < best_err:
                best, best_err = q, err
        self.last_ik_error = best_err
        return best

    def _ik_from(self, q: np.ndarray, target_pos: np.ndarray, target_quat: np.ndarray | None,
                 iterations: int, tolerance: float) -> tuple[np.ndarray, float]:
        n_fingers = len(self._finger_idx)
        lower = [*self.lower, *np.minimum(self._finger_open, self._finger_closed)]
        upper = [*self.upper, *np.maximum(self._finger_open, self._finger_closed)]
        ranges = [u - lo for u, lo in zip(upper, lower, strict=True)]
        best, best_err = q.copy(), math.inf
        for _ in range(iterations):
            self._kin_set(q)
            rest = [*q, *[0.0] * n_fingers]
            kwargs = {'lowerLimits': lower, 'upperLimits': upper, 'jointRanges': ranges,
                      'restPoses': rest, 'maxNumIterations': 50, 'residualThreshold': 1e-6}
            if target_quat is not None:
                sol = self._kin.calculateInverseKinematics(
                    self._kin_body, self._tcp_idx, target_pos.tolist(),
                    np.asarray(target_quat, dtype=float).tolist(), **kwargs)
            else:
                sol = self._kin.calculateInverseKinematics(
                    self._kin_body, self._tcp_idx, target_pos.tolist(), **kwargs)
            q = np.clip(np.array(sol[:self.n_joints]), self.lower, self.upper)
            pos, orn = self.forward_kinematics(q)
            err = float(np.linalg.norm(pos - target_pos))
            if target_quat is not None:
                dot = abs(float(np.dot(orn, np.asarray(target_quat, dtype=float))))
                err += 0.1 * 2 * math.acos(min(1.0, dot))   # 0.1 m per rad
            if err < best_err:
                best, best_err = q.copy(), err
            if err < tolerance:
                break
        return best, best_err


def _in_link(pos: np.ndarray, orn: np.ndarray, frame: LinkFrame) -> tuple[np.ndarray, np.ndarray]:
    """World pose (position (3,) m, quaternion xyzw (4,)) of ``frame`` given its link's."""
    if not any(frame.xyz) and not any(frame.rpy):
        return pos, orn
    fpos, forn = pb.multiplyTransforms(pos.tolist(), orn.tolist(), list(frame.xyz),
                                       list(pb.getQuaternionFromEuler(frame.rpy)))
    return np.array(fpos), np.array(forn)
