"""Arm kinematics the grasp policy needs: camera pose (forward kinematics) and grasp IK.

The controller sees the world only through the camera, depth and joint states; to turn a pixel and
a depth into a point on the table it needs where the camera is (forward kinematics), and to put the
gripper there it needs inverse kinematics. Both are properties of the robot model, not of the scene,
so a real arm offers the same. :class:`ArmKinematics` is the interface; implementations wrap a
URDF model or the simulator's kinematic solver.

Arms of 6 or 7 joints: a six-joint arm has (away from singularities) one joint solution per
pose near the seed, and the grasp IK is plain damped least squares. A seven-joint arm has one
joint more than the pose needs; its free motion (the Jacobian's null space) is spent pulling the
arm towards its home pose and away from its joint limits (``redundancy_step``), so that the
solution is repeatable and the elbow does not drift into a limit over a long approach.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_common.redundancy import redundancy_step


class ArmKinematics(Protocol):
    """What :class:`mindgrasp_fsm.grasp_policy.GraspPolicy` asks of a robot model."""

    def camera_pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Camera optical frame (x right, y down, z forward) in the base frame at joints ``q``.

        Returns ``(position (3,) m, rotation (3, 3))``; rotation columns are the optical axes.
        """
        ...

    def tool_position(self, q: np.ndarray) -> np.ndarray:
        """Grasp point between the fingertips in the base frame (m), shape (3,)."""
        ...

    def grasp_ik(self, position: np.ndarray, yaw: float, q_seed: np.ndarray,
                 tilt: float = 0.0, turn_round: bool = True) -> np.ndarray | None:
        """Joints (n,) rad that put the grasp point at ``position`` (m, base frame) with the
        gripper pointing straight down (leaning ``tilt`` rad towards the base axis,
        :func:`grasp_rotation`) and the finger closing axis turned by ``yaw`` (rad) about the
        vertical (or, with ``turn_round``, by ``yaw + pi`` when ``yaw`` has no solution);
        ``None`` when no solution within 1 cm exists."""
        ...


def frame_offset(xyz: tuple[float, ...], rpy: tuple[float, ...]) -> np.ndarray:
    """4x4 transform of a frame at ``xyz`` (3,) m, ``rpy`` (3,) rad (URDF fixed-axis roll,
    pitch, yaw) in its link, e.g. a robot description's TCP or camera mount."""
    return _transform(np.asarray(xyz, dtype=float), Rotation.from_euler('xyz', rpy).as_matrix())


def grasp_rotation(position: np.ndarray, yaw: float, tilt: float = 0.0) -> np.ndarray:
    """Tool rotation (3, 3) for a grasp at ``position`` (3,) m, base frame: the tool's z points
    down, its x (the closing axis of :meth:`UrdfKinematics.down_rotation`) at ``yaw`` rad, then
    the whole tool leans ``tilt`` rad about the horizontal axis across the line from the base
    axis to ``position``, its tip towards the base.

    Why lean: an arm folded near its own base cannot hold the tool vertical above an object
    close to it (the Panda's elbow at its limit found no pose 0.15 m above an object 0.20 m
    from the base axis); with the tip leaning back towards the base the wrist stays further out
    and the same point is reachable. Leaning about the horizontal keeps the tool point where it
    was and a vertical descent vertical.
    """
    c, s = np.cos(yaw), np.sin(yaw)
    down = np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]])
    if tilt == 0.0:
        return down
    radial = np.array([float(position[0]), float(position[1]), 0.0])
    norm = float(np.linalg.norm(radial))
    if norm < 1e-9:
        return down          # on the base axis: no "towards the base"
    across = np.array([-radial[1], radial[0], 0.0]) / norm     # z x radial
    # a positive turn about z x radial takes -z towards -radial: the tip leans to the base
    return Rotation.from_rotvec(tilt * across).as_matrix() @ down


def _transform(xyz: np.ndarray, rot: np.ndarray) -> np.ndarray:
    t = np.eye(4)
    t[:3, :3] = rot
    t[:3, 3] = xyz
    return t


class UrdfKinematics:
    """Forward and inverse kinematics of a serial arm read from its URDF (no simulator).

    Parameters
    ----------
    urdf_path : str or Path
        Robot description (e.g. ``config/robots/urdf/mindgrasp_arm.urdf``).
    joint_names : sequence of str
        The arm joints (6 or 7), base to wrist.
    tool_link, camera_link : str
        Grasp point link (``tcp``) and camera optical frame link.
    tool_offset, camera_offset : ndarray, shape (4, 4), optional
        The grasp point and the camera optical frame in their links (a robot description's TCP
        offset and eye-in-hand camera mount, :mod:`mindgrasp_common.robot_description`); None:
        the link's own frame.
    home : sequence of float, optional
        Home pose (n,) rad: a seven-joint arm's IK pulls its free motion towards it
        (``redundancy_step``); None: mid-range of the joint limits. Unused for six joints.
    """

    def __init__(self, urdf_path: str, joint_names: tuple[str, ...] | list[str],
                 tool_link: str = 'tcp', camera_link: str = 'camera_color_optical_frame',
                 tool_offset: np.ndarray | None = None,
                 camera_offset: np.ndarray | None = None,
                 home: np.ndarray | tuple[float, ...] | list[float] | None = None) -> None:
        import xml.etree.ElementTree as ET

        from mindgrasp_fsm.errors import FsmError

        try:
            root = ET.parse(str(urdf_path)).getroot()
        except (OSError, ET.ParseError) as exc:
            msg = f'Cannot read the robot description {urdf_path}: {exc}. Give a valid URDF file.'
            raise FsmError(msg) from exc
        joints = {}
        for j in root.findall('joint'):
            origin = j.find('origin')
            xyz = np.array([float(v) for v in (origin.get('xyz', '0 0 0') if origin is not None
                                               else '0 0 0').split()])
            rpy = [float(v) for v in (origin.get('rpy', '0 0 0') if origin is not None
                                      else '0 0 0').split()]
            axis_el = j.find('axis')
            axis = np.array([float(v) for v in (axis_el.get('xyz') if axis_el is not None
                                                else '1 0 0').split()])
            limit = j.find('limit')
            joints[j.find('child').get('link')] = {
                'name': j.get('name'), 'type': j.get('type'),
                'parent': j.find('parent').get('link'),
                # URDF rpy: fixed-axis roll, pitch, yaw (Rz(yaw) Ry(pitch) Rx(roll))
                'origin': _transform(xyz, Rotation.from_euler('xyz', rpy).as_matrix()),
                # a fixed joint may say axis 0 0 0 (the Panda's): it never turns
                'axis': axis / (np.linalg.norm(axis) or 1.0),
                'lower': float(limit.get('lower', -np.pi)) if limit is not None else -np.pi,
                'upper': float(limit.get('upper', np.pi)) if limit is not None else np.pi,
            }
        self.joint_names = list(joint_names)
        self._chains = {}
        for link in (tool_link, camera_link):
            chain = []
            cur = link
            while cur in joints:
                chain.append(joints[cur])
                cur = joints[cur]['parent']
            if not chain:
                msg = f'The link {link!r} is not in {urdf_path}; name the tool/camera link there.'
                raise FsmError(msg)
            chain.reverse()
            for name in joint_names:
                if name not in [c['name'] for c in chain]:
                    msg = (f'The joint {name!r} is not on the chain to {link!r} in {urdf_path}; '
                           'check joint_names.')
                    raise FsmError(msg)
            self._chains[link] = chain
        self.tool_link, self.camera_link = tool_link, camera_link
        self._tool_offset = np.eye(4) if tool_offset is None else np.asarray(tool_offset)
        self._camera_offset = np.eye(4) if camera_offset is None else np.asarray(camera_offset)
        by_name = {c['name']: c for c in joints.values()}
        self.lower = np.array([by_name[n]['lower'] for n in joint_names])
        self.upper = np.array([by_name[n]['upper'] for n in joint_names])
        self._index = {n: i for i, n in enumerate(joint_names)}
        self.n_joints = len(self.joint_names)
        self.home = ((self.lower + self.upper) / 2 if home is None
                     else np.asarray(home, dtype=float).reshape(self.n_joints))

    def link_pose(self, q: np.ndarray, link: str) -> np.ndarray:
        """4x4 pose of ``link`` in the base frame at joints ``q`` (rad)."""
        t = np.eye(4)
        rotations = iter(self._joint_rotations(q, link))
        for joint in self._chains[link]:
            t = t @ joint['origin']
            if joint['type'] in ('revolute', 'continuous'):
                t[:3, :3] = t[:3, :3] @ next(rotations)
        return t

    def _joint_rotations(self, q: np.ndarray, link: str) -> np.ndarray:
        """Rotations (n_moving, 3, 3) of the moving joints on the chain to ``link`` at ``q``,
        in chain order (one scipy call for all of them)."""
        chain = [j for j in self._chains[link] if j['type'] in ('revolute', 'continuous')]
        rotvecs = np.array([j['axis'] * float(q[self._index[j['name']]]) for j in chain])
        return Rotation.from_rotvec(rotvecs).as_matrix()

    def camera_pose(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Camera optical frame: position (3,) m and rotation (3, 3) in the base frame."""
        t = self.link_pose(q, self.camera_link) @ self._camera_offset
        return t[:3, 3].copy(), t[:3, :3].copy()

    def tool_position(self, q: np.ndarray) -> np.ndarray:
        """Grasp point (3,) m in the base frame."""
        return (self.link_pose(q, self.tool_link) @ self._tool_offset)[:3, 3].copy()

    @staticmethod
    def down_rotation(yaw: float) -> np.ndarray:
        """Tool frame pointing down (z = -world z) with its x (closing) axis at ``yaw``."""
        return grasp_rotation(np.zeros(3), yaw)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Geometric Jacobian (6, n) of the tool at joints ``q`` (n,) rad: rows linear (m/s) and
        angular (rad/s) velocity in the base frame per rad/s of each joint."""
        return self._fk_jacobian(np.asarray(q, dtype=float))[1]

    def _fk_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Tool pose (4x4) and the geometric Jacobian (6, n) [linear; angular] at ``q``."""
        t = np.eye(4)
        axes = []
        rotations = iter(self._joint_rotations(q, self.tool_link))
        for joint in self._chains[self.tool_link]:
            t = t @ joint['origin']
            if joint['type'] in ('revolute', 'continuous'):
                axes.append((self._index[joint['name']], t[:3, :3] @ joint['axis'],
                             t[:3, 3].copy()))
                t[:3, :3] = t[:3, :3] @ next(rotations)
        t = t @ self._tool_offset
        jac = np.zeros((6, self.n_joints))
        p = t[:3, 3]
        for i, z, o in axes:
            r = p - o
            # z x r written out: np.cross is slow for single 3-vectors
            jac[:3, i] = (z[1] * r[2] - z[2] * r[1], z[2] * r[0] - z[0] * r[2],
                          z[0] * r[1] - z[1] * r[0])
            jac[3:, i] = z
        return t, jac

    def solve(self, position: np.ndarray, rotation: np.ndarray, q_seed: np.ndarray,
              iterations: int = 100) -> tuple[np.ndarray, float, float]:
        """Damped least squares on position + orientation, inside joint limits; a seven-joint
        arm's null-space motion goes towards the home pose (``redundancy_step``).

        Returns ``(q, position error m, orientation error rad)``.
        """
        q = np.clip(np.asarray(q_seed, dtype=float).copy(), self.lower, self.upper)
        lam = 0.01
        w = np.array([1.0, 1.0, 1.0, 0.3, 0.3, 0.3])   # orientation weighs less (rad vs m)
        for _ in range(iterations):
            t, jac = self._fk_jacobian(q)
            e = self._error(t, position, rotation)
            if np.linalg.norm(e[:3]) < 2e-4 and np.linalg.norm(e[3:]) < 2e-3:
                break
            jw = jac * w[:, None]
            step = jw.T @ np.linalg.solve(jw @ jw.T + lam ** 2 * np.eye(6), e * w)
            if self.n_joints > 6:
                step = step + redundancy_step(jw, q, self.home, self.lower, self.upper)
            n = np.linalg.norm(step)
            if n > 0.3:
                step *= 0.3 / n
            q = np.clip(q + step, self.lower, self.upper)
        t = self.link_pose(q, self.tool_link) @ self._tool_offset
        e = self._error(t, position, rotation)
        return q, float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:]))

    @staticmethod
    def _error(t: np.ndarray, position: np.ndarray, rotation: np.ndarray) -> np.ndarray:
        dp = np.asarray(position) - t[:3, 3]
        r = rotation @ t[:3, :3].T
        # rotation vector of r (small-angle safe), written out: this runs in every IK iteration
        # and scipy's Rotation.from_matrix (which re-orthonormalises) costs ~10x more here
        angle = np.arccos(np.clip((np.trace(r) - 1) / 2, -1.0, 1.0))
        if angle < 1e-9:
            dr = np.zeros(3)
        else:
            axis = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
            s = np.linalg.norm(axis)
            dr = axis / s * angle if s > 1e-9 else np.zeros(3)
        return np.concatenate([dp, dr])

    def grasp_ik(self, position: np.ndarray, yaw: float, q_seed: np.ndarray,
                 tilt: float = 0.0, turn_round: bool = True) -> np.ndarray | None:
        """Joints with the tool at ``position`` pointing down (leaning ``tilt`` rad towards the
        base axis, :func:`grasp_rotation`), closing axis at ``yaw``; if that has no solution and
        ``turn_round``, at ``yaw + pi`` (the same grasp with the hand turned round). None when
        none is within 1 cm / 0.05 rad."""
        for y in (yaw, yaw + np.pi) if turn_round else (yaw,):
            q, ep, er = self.solve(position, grasp_rotation(position, y, tilt), q_seed)
            if ep <= 0.01 and er <= 0.05:
                return q
        return None
