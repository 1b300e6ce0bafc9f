"""The PyBullet simulation of the MIndGrasp arm, gripper, eye-in-hand RGB-D camera and scene
(ROS-free; the node :mod:`mindgrasp_sim.sim_node` is a thin layer on top).

Typical use::

    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation
    sim = Simulation(scene='set_locations', seed=0, camera=CameraConfig(128, 128, 10.0))
    sim.set_joint_velocities(np.array([0.1, 0, 0, 0, 0, 0]))   # rad/s
    sim.step(240)                                              # one simulated second
    rgb, depth = sim.render_camera()                           # uint8 (H, W, 3), float32 (H, W) m
    sim.close()

Joint control follows a ros2_control forward velocity controller on a position-controlled arm:
each physics step integrates the commanded (clipped) velocity into a joint reference that a stiff,
torque-limited PD motor tracks, so the arm holds still without drift when the command is zero and
stops at its position limits. Two simulations with the same seed and command sequence produce
identical states and images (DIRECT mode, deterministic overlapping pairs).

:class:`Simulation` is composed from one module per role (its methods come from their mixins):
:mod:`~mindgrasp_sim.world` (ground, robots, objects, scene and resets),
:mod:`~mindgrasp_sim.arm_control` (commands, the physics step, joint and hand readings),
:mod:`~mindgrasp_sim.camera` (:class:`~mindgrasp_sim.camera.CameraConfig`, images),
:mod:`~mindgrasp_sim.kinematics` (poses, FK, Jacobian, IK on a kinematic twin) and
:mod:`~mindgrasp_sim.bullet_client` (PyBullet plumbing); this module builds the world and owns
the state they share.

Realism (off by default): ``realism='default'`` (or a :class:`~mindgrasp_sim.realism.RealismProfile`
or a YAML path) adds what a real set-up has: noisy depth with invalid pixels, colour noise and
lighting, a camera mounted off its URDF pose, encoder noise, a lag of the velocity controller,
objects that differ in mass, friction, size and hue, and finger contacts on any surface. The
sensor readings (:meth:`Simulation.render_camera`, :meth:`Simulation.joint_readings`,
:meth:`Simulation.gripper_state`) carry it; the ground truth (:meth:`Simulation.joint_positions`,
:meth:`Simulation.objects`, :meth:`Simulation.held_object`) stays exact for the bookkeeping.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
from pathlib import Path

import numpy as np

from mindgrasp_common.geometry import top_down_quat
from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
from mindgrasp_common.robot import DEFAULT_ROBOT, HOME_POSE
from mindgrasp_common.robot_description import (
    RobotDescription,
    RobotDescriptionError,
    load_robot,
)
from mindgrasp_common.types import SceneObject
from mindgrasp_sim.arm_control import ARM_POSITION_GAIN, ArmControlMixin, _Robot
from mindgrasp_sim.bullet_client import _c_stdout_to_stderr, _Client
from mindgrasp_sim.camera import CameraConfig, CameraMixin
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.kinematics import KinematicsMixin
from mindgrasp_sim.pybullet_quiet import pb
from mindgrasp_sim.realism import Realism, RealismProfile
from mindgrasp_sim.scene import ObjectSpec, SceneSpec
from mindgrasp_sim.world import WorldMixin

ROBOTS = ('user', 'trainer')


class Simulation(WorldMixin, ArmControlMixin, CameraMixin, KinematicsMixin):
    """PyBullet world: the user's arm (and optionally the trainer's ghost arm), objects, camera.

    Parameters
    ----------
    scene : str | Path
        ``'set_locations'``, ``'random_locations'`` (names in ``config/scenes``) or a
        YAML path.
    seed : int
        Seed of the random object layout (random scenes); same seed, same layout.
    camera : CameraConfig | None
        Eye-in-hand camera (default 128 x 128 px, 10 Hz, 60 deg vertical field of view).
    physics_hz : float
        Physics rate (Hz); each :meth:`step` advances ``1 / physics_hz`` s.
    trainer_robot : bool
        Also load the green, semi-transparent, non-colliding training robot.
    gui : bool
        Open the PyBullet window (needs a display); DIRECT (headless) otherwise.
    n_objects : int | None
        Number of random objects (random scenes); None: the scene file's number.
    urdf : str | Path | None
        A URDF (path or ``package://`` URI) in place of the robot description's, with the same
        joint and link names; None: the description's URDF.
    solver_iterations : int
        Constraint solver iterations per step (contacts and motors; 50 holds grasps well).
    realism : RealismProfile | str | Path | None
        Sensor noise and physical spread (:mod:`mindgrasp_sim.realism`): a profile, its name
        (``'default'``, ``'none'``) or a YAML path; None is ``'none'`` (a perfect world).
    realism_seed : int
        Seed of the realism draws; with the layout seed and the trial number (resets since the
        scene was loaded) it fixes every noise sample, so the same seeds give the same images.
    robot : RobotDescription | str | Path
        The arm (:mod:`mindgrasp_common.robot_description`): a shipped name (``'mindgrasp_arm'``,
        ``'xarm6'``), the path of a robot YAML file, or a loaded description.
    """

    def __init__(self, scene: str | Path = 'set_locations', seed: int = 0,
                 camera: CameraConfig | None = None, physics_hz: float = 240.0,
                 trainer_robot: bool = False, gui: bool = False, n_objects: int | None = None,
                 urdf: str | Path | None = None, solver_iterations: int = 50,
                 realism: RealismProfile | str | Path | None = None,
                 realism_seed: int = 0,
                 robot: RobotDescription | str | Path = DEFAULT_ROBOT) -> None:
        if not (isinstance(physics_hz, (int, float)) and math.isfinite(physics_hz)
                and 30.0 <= physics_hz <= 10000.0):
            msg = f'physics_hz must be a rate in 30..10000 Hz, got {physics_hz!r}; the ' \
                  'default 240.0 suits contacts.'
            raise SimError(msg)
        if n_objects is not None and (not isinstance(n_objects, (int, np.integer))
                                      or n_objects < 0):
            msg = f'n_objects must be None or an integer >= 0, got {n_objects!r}.'
            raise SimError(msg)
        self.camera = camera or CameraConfig()
        self._trial = 0
        self.physics_hz = float(physics_hz)
        self.dt = 1.0 / self.physics_hz
        self.gui = bool(gui)
        self.n_objects = n_objects
        try:
            self.robot = load_robot(robot)
        except RobotDescriptionError as exc:
            raise SimError(str(exc)) from None
        #: arm joints (n,) base to wrist, and the gripper joints, as the description names them
        self.joint_names: tuple[str, ...] = self.robot.arm_joints
        #: number of arm joints (6 or 7)
        self.n_joints = len(self.joint_names)
        self.realism = Realism(realism, realism_seed, self.n_joints)
        # PD motor gains per arm joint (see ARM_POSITION_GAIN)
        self._arm_position_gains = (ARM_POSITION_GAIN,) * self.n_joints
        self._arm_velocity_gains = (1.0,) * self.n_joints
        self.finger_names: tuple[str, ...] = self.robot.gripper.joints
        self.home_pose = np.array(self.robot.home_pose, dtype=float)
        # gripper joint positions (n_fingers,) of closure 0 and 1
        self._finger_open = np.array(self.robot.gripper.open)
        self._finger_closed = np.array(self.robot.gripper.closed)
        try:
            self.urdf = resolve_path(urdf or self.robot.urdf, 'mindgrasp_sim')
        except ResourceNotFoundError as exc:
            raise SimError(f'{exc} Give an existing URDF.') from None
        if not self.urdf.is_file():
            msg = f'Robot description {str(self.urdf)!r} does not exist; give an existing URDF.'
            raise SimError(msg)
        if self.gui and sys.platform.startswith('linux') and not os.environ.get('DISPLAY'):
            msg = 'gui=True needs a display, but DISPLAY is not set; run with gui=False ' \
                  '(headless) or from a desktop session.'
            raise SimError(msg)
        with _c_stdout_to_stderr():
            self._p = _Client(connection_mode=pb.GUI if self.gui else pb.DIRECT)
            self._kin = _Client(connection_mode=pb.DIRECT)   # kinematic twin for IK / FK
        p = self._p
        p.setPhysicsEngineParameter(fixedTimeStep=self.dt, numSolverIterations=solver_iterations,
                                    deterministicOverlappingPairs=1, numSubSteps=0)
        p.setGravity(0, 0, -9.81)
        if self.gui:
            p.configureDebugVisualizer(pb.COV_ENABLE_GUI, 0)
            p.resetDebugVisualizerCamera(1.4, 30, -35, [0.2, 0, 0.2])
        self._renderer = pb.ER_TINY_RENDERER
        if self.camera.renderer == 'egl':
            self._renderer = self._load_egl()
        # the camera draws the ground itself unless a GPU renderer or a window shows it
        self._ground_visual = self.gui or self._renderer != pb.ER_TINY_RENDERER
        self._ground = self._make_ground()
        self._robots: dict[str, _Robot] = {}
        self._robots['user'] = self._load_robot(p, ghost=False)
        if trainer_robot:
            self._robots['trainer'] = self._load_robot(p, ghost=True)
        with _c_stdout_to_stderr():
            self._kin_body = self._kin.loadURDF(str(self.urdf), useFixedBase=True)
        names = {p.getJointInfo(self._robots['user'].body, j)[1].decode():
                 j for j in range(p.getNumJoints(self._robots['user'].body))}
        self._names = names
        # pybullet's link i is the child of joint i
        links = {p.getJointInfo(self._robots['user'].body, j)[12].decode(): j
                 for j in range(p.getNumJoints(self._robots['user'].body))}
        missing = {'joints': [n for n in (*self.joint_names, *self.finger_names)
                              if n not in names],
                   'links': [n for n in (self.robot.tcp.link, self.robot.camera.link)
                             if n not in links]}
        if any(missing.values()):
            lacks = ' and '.join(f'the {k} {v}' for k, v in missing.items() if v)
            msg = (f'The URDF {str(self.urdf)!r} lacks {lacks}, which the robot description '
                   f'{self.robot.name!r} names; give the URDF of that robot or fix the '
                   f'description {str(self.robot.path)!r}.')
            raise SimError(msg)
        self._arm_idx = [names[n] for n in self.joint_names]
        self._finger_idx = [names[n] for n in self.finger_names]
        # (position in finger_names, joint index) of the gripper joints with a motor: the
        # URDF's mimic joints follow their leader through a gear constraint instead
        followers = {m[0] for m in self.robot.gripper.mimic}
        self._finger_driven = [(k, j) for k, (j, n) in enumerate(
            zip(self._finger_idx, self.finger_names, strict=True)) if n not in followers]
        for r in self._robots.values():
            self._couple_mimic_joints(p, r.body, names)
        self._tcp_idx = links[self.robot.tcp.link]
        # the base and the links welded to it (the xArm's link_base under its world link) stand
        # on the ground: their contact with it is no collision
        self._base_links = {-1}
        for j in range(p.getNumJoints(self._robots['user'].body)):
            info = p.getJointInfo(self._robots['user'].body, j)
            if info[2] == pb.JOINT_FIXED and info[16] in self._base_links:
                self._base_links.add(j)
        self._cam_idx = links[self.robot.camera.link]
        infos = [p.getJointInfo(self._robots['user'].body, j) for j in self._arm_idx]
        self.lower = np.array([i[8] for i in infos])
        self.upper = np.array([i[9] for i in infos])
        self.max_velocity = np.array([i[11] for i in infos])
        # position error (rad) per rad/s of the motor's velocity aim (see _track)
        self._lag_scale = self.dt / ARM_POSITION_GAIN
        self.max_effort = np.array([i[10] for i in infos])
        finfo = [p.getJointInfo(self._robots['user'].body, j) for j in self._finger_idx]
        self._finger_effort = [i[10] for i in finfo]
        self._finger_velocity = [i[11] for i in finfo]
        self._finger_links = {j: n for j, n in zip(self._finger_idx, self.finger_names,
                                                   strict=True)}
        # the wrist camera leaves out the links it cannot see (TinyRenderer only; the GUI and
        # an OpenGL renderer draw the whole arm), when the robot has meshes to leave out (the
        # shipped arm's few primitives cost less than the test): each link's visual shapes'
        # colours (rgba)
        visuals = p.getVisualShapeData(self._robots['user'].body)
        self._cull_enabled = (not self.gui and self._renderer == pb.ER_TINY_RENDERER
                              and any(v[2] == pb.GEOM_MESH for v in visuals))
        self._visual_colours: dict[int, list[tuple[float, ...]]] = {}
        for v in visuals:
            self._visual_colours.setdefault(v[1], []).append(tuple(v[7]))
        self._visual_links = list(self._visual_colours)
        tan_y = math.tan(math.radians(self.camera.fov_deg) / 2.0)
        self._cull_tan = (tan_y * self.camera.width / self.camera.height, tan_y)
        self._objects: list[tuple[ObjectSpec, int]] = []
        self._step_count = 0
        self._proj = None
        self._rays: np.ndarray | None = None
        self._ground_rgba = np.uint32(0)
        self.last_ik_error = 0.0
        self._scene: SceneSpec | None = None
        self.seed = int(seed)
        self.load_scene(scene, seed=seed)

    @property
    def robots(self) -> tuple[str, ...]:
        """Names of the simulated arms: ``('user',)`` or ``('user', 'trainer')``."""
        return tuple(self._robots)

    # read-only handles for tools that inspect the robot itself (``mindgrasp robot check``,
    # ``robot_import home``): the world's pybullet client, the arm's body, the finger joints
    # and the kinematic twin
    @property
    def client(self):
        """The world's pybullet client (``pybullet_utils.bullet_client``)."""
        return self._p

    def body(self, robot: str = 'user') -> int:
        """PyBullet body id of ``robot``'s arm in :attr:`client`."""
        return self._robot(robot).body

    @property
    def finger_joint_indices(self) -> list[int]:
        """PyBullet joint indices of the hand's finger joints, in the robot YAML's order."""
        return list(self._finger_idx)

    @property
    def kinematic_twin(self) -> tuple[object, int]:
        """``(client, body)`` of the kinematic twin used for IK / FK (never stepped)."""
        return self._kin, self._kin_body

    @property
    def arm_joint_indices(self) -> list[int]:
        """PyBullet joint indices of the arm's joints, in the robot YAML's order."""
        return list(self._arm_idx)

    @property
    def camera_link_index(self) -> int:
        """PyBullet link index of the wrist camera's link."""
        return self._cam_idx

    def set_twin_joints(self, q: np.ndarray) -> None:
        """Put the kinematic twin's arm at ``q`` (rad, one per arm joint)."""
        self._kin_set(q)

    @property
    def layout_seed(self) -> int:
        """Seed of the current object layout (random scenes)."""
        return self._layout_seed

    @property
    def time(self) -> float:
        """Simulated time since the last reset (s)."""
        return self._step_count * self.dt

    @property
    def step_count(self) -> int:
        """Physics steps since the last reset."""
        return self._step_count

    def _robot(self, robot: str) -> _Robot:
        try:
            return self._robots[robot]
        except KeyError:
            hint = (' (start the simulation with trainer_robot=True)' if robot == 'trainer'
                    else '')
            msg = f'Unknown robot {robot!r}; use one of {sorted(self._robots)}{hint}.'
            raise SimError(msg) from None

    def close(self) -> None:
        """Disconnect from PyBullet (the object is unusable afterwards)."""
        for client in (self._p, self._kin):
            with contextlib.suppress(pb.error):
                client.disconnect()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ['HOME_POSE', 'SceneObject', 'Simulation', 'top_down_quat']
