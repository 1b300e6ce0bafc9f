"""The PyBullet simulation of the MIndGrasp arm, gripper, eye-in-hand RGB-D camera and scene
(ROS-free; the node :mod:`mindgrasp_sim.sim_node` is a thin layer on top).

Typical use::

    from mindgrasp_sim.simulation import Simulation, CameraConfig
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
import ctypes
import functools
import math
import os
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_common.geometry import top_down_quat
from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
from mindgrasp_common.robot import DEFAULT_ROBOT, HOME_POSE
from mindgrasp_common.robot_description import (
    LinkFrame,
    RobotDescription,
    RobotDescriptionError,
    load_robot,
)
from mindgrasp_common.types import SceneObject
from mindgrasp_sim.control import validate_velocities
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.pybullet_quiet import BulletClient, pb
from mindgrasp_sim.realism import Realism, RealismProfile
from mindgrasp_sim.scene import ObjectSpec, SceneSpec, load_scene

#: PD motor position gain (pybullet's per-step error fraction): stiff, so gravity sag < 1 mrad
ARM_POSITION_GAIN = 0.8
_GOVERNOR_TOLERANCE = 1.05
#: growth (m) of a link's collision bounding box before the wrist camera leaves the link out
#: of a frame for lying outside its view (visual shapes may stick out of collision shapes)
CULL_MARGIN = 0.05
GROUND_RGBA = (0.78, 0.77, 0.74, 1.0)
TRAINER_RGBA = (0.1, 0.85, 0.1, 0.35)
ROBOTS = ('user', 'trainer')
#: default third-person scene camera (m, world): behind-right of the base, looking at the objects
SCENE_EYE = (-0.55, -1.0, 0.9)
SCENE_TARGET = (0.25, 0.0, 0.3)
SKY_RGB = (70, 80, 100)
#: camera light: mostly ambient so the task colours stay saturated (original thresholds 0.7/0.3)
_LIGHT = {'lightDirection': [0.4, -0.3, 1.0], 'lightAmbientCoeff': 0.55,
          'lightDiffuseCoeff': 0.5, 'lightSpecularCoeff': 0.0}


class _Client(BulletClient):
    """BulletClient that binds each pybullet function to its client once: the stock one builds a
    new ``functools.partial`` (after an ``inspect`` check) on every call, thousands per simulated
    second in the physics loop."""

    def __init__(self, connection_mode: int) -> None:
        # BulletClient connects with options='', and pybullet's C code prints "argv[0]=" for any
        # options string: two lines per Simulation, per trial in an experiment. pb.connect
        # without options prints nothing. (The attributes are the ones BulletClient sets.)
        self._shapes: dict = {}
        self._pid = os.getpid()
        self._client = pb.connect(connection_mode)

    def __getattr__(self, name: str) -> object:
        attribute = super().__getattr__(name)
        if name != 'disconnect' and isinstance(attribute, functools.partial):
            self.__dict__[name] = attribute
        return attribute


@contextlib.contextmanager
def _c_stdout_to_stderr() -> Iterator[None]:
    """PyBullet's C code may print to stdout while it connects (the GUI's OpenGL report) or loads
    a URDF (its importer's warnings); send it to stderr so stdout stays the caller's (e.g. a
    command's --json line)."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        libc.fflush(None)                # C stdio buffers go out while fd 1 is still stderr
        os.dup2(saved, 1)
        os.close(saved)


@dataclass
class CameraConfig:
    """Eye-in-hand RGB-D camera settings.

    width, height: image size (px); rate_hz: publishing rate (Hz, used by the node);
    fov_deg: vertical field of view (deg); near, far: clipping planes (m); renderer: 'tiny'
    (PyBullet's CPU TinyRenderer, the default) or 'egl' (OpenGL through the EGL plugin: fast with a
    GPU, slow with a software driver; falls back to 'tiny' where EGL is missing).
    """

    width: int = 128
    height: int = 128
    rate_hz: float = 10.0
    fov_deg: float = 60.0
    near: float = 0.01
    far: float = 3.0
    renderer: str = 'tiny'


    def __post_init__(self) -> None:
        for name in ('width', 'height'):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or not 8 <= value <= 4096:
                msg = f'Camera {name} must be an integer number of pixels in 8..4096, got ' \
                      f'{value!r}; use e.g. 128 or 640.'
                raise SimError(msg)
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            msg = f'Camera rate_hz must be a positive number of Hz, got {self.rate_hz!r}; use ' \
                  'e.g. 10.0.'
            raise SimError(msg)
        if not 5.0 <= self.fov_deg <= 150.0:
            msg = f'Camera fov_deg must be in 5..150 degrees, got {self.fov_deg!r}.'
            raise SimError(msg)
        if self.renderer not in ('tiny', 'egl'):
            msg = f"Camera renderer must be 'tiny' or 'egl', got {self.renderer!r}."
            raise SimError(msg)
        if not 0 < self.near < self.far:
            msg = f'Camera clipping planes must satisfy 0 < near < far, got near={self.near!r}, ' \
                  f'far={self.far!r}.'
            raise SimError(msg)


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


class Simulation:
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

    # ------------------------------------------------------------------ world building
    def _load_egl(self) -> int:
        import pkgutil
        import warnings

        loader = pkgutil.get_loader('eglRenderer')
        if loader is not None and self._p.loadPlugin(loader.get_filename(),
                                                     '_eglRendererPlugin') >= 0:
            return pb.ER_BULLET_HARDWARE_OPENGL
        warnings.warn('The EGL renderer plugin could not be loaded (no EGL on this machine); '
                      "rendering with TinyRenderer instead. Use camera renderer 'tiny'.",
                      stacklevel=3)
        self.camera.renderer = 'tiny'
        return pb.ER_TINY_RENDERER

    def _make_ground(self) -> int:
        p = self._p
        col = p.createCollisionShape(pb.GEOM_PLANE)
        if self._ground_visual:
            vis = p.createVisualShape(pb.GEOM_BOX, halfExtents=[2.0, 2.0, 0.005],
                                      visualFramePosition=[0, 0, -0.005], rgbaColor=GROUND_RGBA)
        else:
            # the camera sees the ground through render_camera's exact plane; a mesh covering the
            # whole image would cost TinyRenderer ~0.3 us per pixel. A speck far below stops
            # pybullet from drawing the collision plane instead.
            vis = p.createVisualShape(pb.GEOM_BOX, halfExtents=[1e-4] * 3,
                                      visualFramePosition=[0, 0, -50.0], rgbaColor=GROUND_RGBA)
        body = p.createMultiBody(0, col, vis, [0, 0, 0])
        p.changeDynamics(body, -1, lateralFriction=0.6, restitution=0.0)
        return body

    def _ground_colour(self) -> np.ndarray:
        """The ground's colour as TinyRenderer shades it under the camera light (rgb uint8)."""
        k = self._kin
        vis = k.createVisualShape(pb.GEOM_BOX, halfExtents=[0.5, 0.5, 0.005],
                                  visualFramePosition=[0, 0, -0.005], rgbaColor=GROUND_RGBA)
        body = k.createMultiBody(0, -1, vis, [10.0, 0, 0])
        view = k.computeViewMatrix([10.0, 0, 1.0], [10.0, 0, 0], [1, 0, 0])
        proj = k.computeProjectionMatrixFOV(20.0, 1.0, 0.1, 3.0)
        rgba = k.getCameraImage(8, 8, view, proj, renderer=pb.ER_TINY_RENDERER, shadow=0,
                                flags=pb.ER_NO_SEGMENTATION_MASK, **_LIGHT)[2]
        k.removeBody(body)
        return np.asarray(rgba, dtype=np.uint8).reshape(8, 8, 4)[4, 4, :3].copy()

    def _load_robot(self, p: BulletClient, ghost: bool) -> _Robot:
        flags = pb.URDF_USE_INERTIA_FROM_FILE
        if not ghost:
            flags |= pb.URDF_USE_SELF_COLLISION | pb.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        with _c_stdout_to_stderr():
            body = p.loadURDF(str(self.urdf), useFixedBase=True, flags=flags)
        n = p.getNumJoints(body)
        for link in range(-1, n):
            if ghost:
                # the trainer's arm is a prompt, not a body: it touches nothing
                p.setCollisionFilterGroupMask(body, link, 0, 0)
                p.changeVisualShape(body, link, rgbaColor=TRAINER_RGBA)
            name = p.getJointInfo(body, link)[1].decode() if link >= 0 else ''
            if name in self.robot.gripper.joints:
                p.changeDynamics(body, link, lateralFriction=1.2, spinningFriction=0.003,
                                 rollingFriction=0.0, frictionAnchor=1)
            else:
                p.changeDynamics(body, link, lateralFriction=0.8)
            if link >= 0:
                p.changeDynamics(body, link, linearDamping=0.0, angularDamping=0.0,
                                 jointDamping=0.05)
        if not ghost and not self.robot.gripper.self_collision:
            self._disable_gripper_self_collision(p, body)
        if not ghost:
            self._disable_welded_self_collision(p, body)
        # velocity motors off: joints are driven by the PD reference in step()
        return _Robot(body=body, q_ref=self.home_pose.copy(), v_cmd=np.zeros(self.n_joints),
                      v_applied=np.zeros(self.n_joints))

    def _disable_gripper_self_collision(self, p: BulletClient, body: int) -> None:
        """No contacts among the gripper's links and the links they hang from (the
        description's ``self_collision: false``)."""
        joints = {p.getJointInfo(body, j)[1].decode(): j for j in range(p.getNumJoints(body))}
        links = set()
        for name in self.robot.gripper.joints:
            j = joints[name]
            links |= {j, p.getJointInfo(body, j)[16]}   # the joint's child link and its parent
        for a in links:
            for b in links:
                if a < b:
                    p.setCollisionFilterPair(body, body, a, b, 0)

    def _disable_welded_self_collision(self, p: BulletClient, body: int) -> None:
        """No contacts between links welded by fixed joints, nor between such a group and the
        link its moving joint turns on. PyBullet's EXCLUDE_PARENT spares a link and its direct
        parent only; the Panda's hand hangs from link 7 through a virtual link 8, and their
        meshes overlap by design (the hand's collision with link 7 braked joint 7)."""
        n = p.getNumJoints(body)
        info = [p.getJointInfo(body, j) for j in range(n)]
        # the rigid group of each link: the link its chain of fixed joints hangs from (-1: base)
        root = {-1: -1}
        for j in range(n):      # PyBullet numbers a parent link before its children
            root[j] = root[info[j][16]] if info[j][2] == pb.JOINT_FIXED else j
        for a in range(n):
            if root[a] == a:
                continue
            # welded to its group's root, and to the link that root turns on
            hinge = info[root[a]][16] if root[a] >= 0 else None
            for b in {root[a], hinge} - {None, info[a][16]}:
                p.setCollisionFilterPair(body, body, a, b, 0)
            for c in range(a):
                if root[c] == root[a] and c != info[a][16]:
                    p.setCollisionFilterPair(body, body, a, c, 0)

    def _couple_mimic_joints(self, p: BulletClient, body: int, names: dict[str, int]) -> None:
        """Tie each URDF mimic joint of the gripper to its leader with a gear constraint
        (position = multiplier * leader + offset), its own motor off. PyBullet ignores
        ``<mimic>``: driven one by one with soft motors, the xArm gripper's finger pads turned
        out under load (past their limits) and the object slipped out at the lift."""
        for joint, leader, multiplier, offset in self.robot.gripper.mimic:
            j, lead = names[joint], names[leader]
            p.setJointMotorControl2(body, j, pb.VELOCITY_CONTROL, force=0.0)
            info = p.getJointInfo(body, j)
            c = p.createConstraint(body, lead, body, j, pb.JOINT_GEAR, list(info[13]),
                                   [0, 0, 0], [0, 0, 0])
            # the gear holds q_j = multiplier * q_leader (+ offset, as a position target)
            p.changeConstraint(c, gearRatio=-multiplier, gearAuxLink=-1, erp=0.8,
                               relativePositionTarget=offset, maxForce=info[10])

    def _spawn(self, spec: ObjectSpec) -> int:
        p = self._p
        s = spec.size
        if spec.shape == 'cube':
            col = p.createCollisionShape(pb.GEOM_BOX, halfExtents=[s / 2] * 3)
            vis = p.createVisualShape(pb.GEOM_BOX, halfExtents=[s / 2] * 3, rgbaColor=spec.rgba)
        elif spec.shape == 'cylinder':
            col = p.createCollisionShape(pb.GEOM_CYLINDER, radius=s / 2, height=s)
            vis = p.createVisualShape(pb.GEOM_CYLINDER, radius=s / 2, length=s,
                                      rgbaColor=spec.rgba)
        elif spec.shape == 'sphere':
            col = p.createCollisionShape(pb.GEOM_SPHERE, radius=s / 2)
            vis = p.createVisualShape(pb.GEOM_SPHERE, radius=s / 2, rgbaColor=spec.rgba)
        else:
            scale = [spec.scale] * 3
            col = p.createCollisionShape(pb.GEOM_MESH, fileName=spec.mesh, meshScale=scale)
            vis = p.createVisualShape(pb.GEOM_MESH, fileName=spec.mesh, meshScale=scale,
                                      rgbaColor=spec.rgba)
        orn = p.getQuaternionFromEuler([0, 0, spec.yaw])
        body = p.createMultiBody(spec.mass, col, vis, spec.position, orn)
        p.changeDynamics(body, -1, lateralFriction=spec.friction,
                         rollingFriction=spec.rolling_friction,
                         spinningFriction=spec.spinning_friction, restitution=0.0,
                         linearDamping=0.04, angularDamping=0.04,
                         # objects at rest sleep (most of the physics cost otherwise); a touch
                         # of the hand wakes them
                         activationState=pb.ACTIVATION_STATE_ENABLE_SLEEPING)
        return body

    # ------------------------------------------------------------------ scene and reset
    def load_scene(self, scene: str | Path | dict, seed: int | None = None) -> None:
        """Load a scene (name, YAML path or mapping) and reset; ``seed`` None: the scene's own."""
        spec = load_scene(scene)
        self._scene = spec
        self.seed = int(spec.seed if seed is None else seed)
        self._layout_seed = self.seed
        self._layout = spec.draw(self._layout_seed, self.n_objects)
        self._trial = 0      # realism draws depend on the layout seed and the resets since here
        self.reset()

    @property
    def scene(self) -> SceneSpec:
        """The loaded :class:`~mindgrasp_sim.scene.SceneSpec`."""
        assert self._scene is not None
        return self._scene

    def reset(self, new_random_draw: bool = False, seed: int | None = None) -> None:
        """Robots home, grippers open, time 0; objects back to the layout.

        new_random_draw: draw a new layout (random scenes): from ``seed`` if given, else the next
        seed of the sequence (previous layout seed + 1).
        """
        if new_random_draw or seed is not None:
            if self.scene.random is None and new_random_draw:
                msg = f'Scene {self.scene.name!r} has no random section, so a new random draw is ' \
                      'not possible; load a random scene (e.g. random_locations) first.'
                raise SimError(msg)
            self._layout_seed = int(seed) if seed is not None else self._layout_seed + 1
            self._layout = self.scene.draw(self._layout_seed, self.n_objects)
        p = self._p
        for _, body in self._objects:
            p.removeBody(body)
        # per-trial realism draws (camera mount, lighting, encoder offsets, object spread)
        self.realism.begin_trial(self._layout_seed, self._trial)
        self._trial += 1
        specs = [self.realism.spread_object(spec) for spec in self._layout]
        self._objects = [(spec, self._spawn(spec)) for spec in specs]
        for robot in self._robots.values():
            for i, j in enumerate(self._arm_idx):
                self._reset_arm_joint(robot, j, self.home_pose[i], 0.0)
            for j, q in zip(self._finger_idx, self._finger_open, strict=True):
                p.resetJointState(robot.body, j, q, 0.0)
            robot.q_ref = self.home_pose.copy()
            robot.command(np.zeros(self.n_joints))
            robot.apply(np.zeros(self.n_joints))
            robot.closure = 0.0
            robot.gripper_dirty = True
            robot.holding = False
        self._step_count = 0

    # ------------------------------------------------------------------ time and commands
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

    # ------------------------------------------------------------------ state
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

    def objects(self) -> list[SceneObject]:
        """Current state of all scene objects (id = index in the scene layout)."""
        out = []
        for i, (spec, body) in enumerate(self._objects):
            pos, orn = self._p.getBasePositionAndOrientation(body)
            out.append(SceneObject(object_id=i, colour=spec.colour, shape=spec.shape,
                                   position=np.array(pos), orientation=np.array(orn),
                                   size=spec.size, mass=spec.mass, rgba=spec.rgba))
        return out

    def object_velocity(self, obj: SceneObject | int) -> np.ndarray:
        """Linear velocity (3,) m/s of an object."""
        body = self._objects[obj if isinstance(obj, int) else obj.object_id][1]
        return np.array(self._p.getBaseVelocity(body)[0])

    def _finger_contacts(self, robot_body: int) -> dict[int, set[int]]:
        """Object body -> finger joint indices touching it (one contact query)."""
        objects = {b for _, b in self._objects}
        out: dict[int, set[int]] = {}
        for c in self._p.getContactPoints(bodyA=robot_body):
            if c[2] in objects and c[3] in self._finger_links:
                out.setdefault(c[2], set()).add(c[3])
        return out

    def held_object(self, robot: str = 'user') -> SceneObject | None:
        """The object touched by >= 2 fingers and not touching the ground, else None."""
        r = self._robot(robot)
        for body, fingers in self._finger_contacts(r.body).items():
            if len(fingers) >= 2 and not self._p.getContactPoints(body, self._ground):
                # the common SceneObject has no PyBullet body: match through the layout index
                return next(o for o in self.objects() if self._objects[o.object_id][1] == body)
        return None

    def collisions(self, robot: str = 'user') -> list[str]:
        """Unwanted contacts of the arm: with the ground (any link but the fingertips) and with
        itself, as ``'<link> - <link|ground>'`` strings."""
        r = self._robot(robot)
        names = {j: self._p.getJointInfo(r.body, j)[12].decode()
                 for j in range(self._p.getNumJoints(r.body))}
        names[-1] = 'base_link'
        out = set()
        for c in self._p.getContactPoints(r.body, self._ground):
            if c[3] not in self._finger_links and c[3] not in self._base_links:
                out.add(f'{names[c[3]]} - ground')
        for c in self._p.getContactPoints(r.body, r.body):
            a, b = sorted((names[c[3]], names[c[4]]))
            out.add(f'{a} - {b}')
        return sorted(out)

    # ------------------------------------------------------------------ camera
    def camera_intrinsics(self) -> tuple[np.ndarray, int, int]:
        """Pinhole matrix K (3, 3) in pixels (ROS convention: pixel centres at integers), width,
        height."""
        c = self.camera
        fy = c.height / 2.0 / math.tan(math.radians(c.fov_deg) / 2.0)
        k = np.array([[fy, 0.0, (c.width - 1) / 2.0], [0.0, fy, (c.height - 1) / 2.0],
                      [0.0, 0.0, 1.0]])
        return k, c.width, c.height

    def render_camera(self, robot: str = 'user', exact: bool = False
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Render the eye-in-hand camera: rgb uint8 (H, W, 3) and depth float32 (H, W), metres
        along the optical axis (``far`` where nothing is hit).

        With a realism profile the image is what the camera delivers: seen from the camera's
        physical pose (mount error), with colour and depth noise and invalid depth pixels (NaN or
        0). ``exact=True`` renders the perfect image from the URDF pose.
        """
        c = self.camera
        p = self._p
        pos, orn = self.camera_pose(robot)
        rot = Rotation.from_quat(orn).as_matrix()
        sensed = not exact and robot == 'user' and self.realism.enabled
        if sensed:
            pos, rot = self.realism.camera_pose(pos, rot)
        target = pos + rot[:, 2]
        up = -rot[:, 1]
        view = p.computeViewMatrix(pos.tolist(), target.tolist(), up.tolist())
        if self._proj is None:
            self._proj = p.computeProjectionMatrixFOV(c.fov_deg, c.width / c.height, c.near, c.far)
        hidden = self._hide_other_robots(robot)
        culled = self._cull_links(robot, pos, rot)
        _, _, rgba, depth_buf, _ = p.getCameraImage(
            c.width, c.height, view, self._proj, renderer=self._renderer, shadow=0,
            flags=pb.ER_NO_SEGMENTATION_MASK, **_LIGHT)
        self._uncull(robot, culled)
        self._unhide(hidden)
        rgba = np.array(rgba, dtype=np.uint8, copy=True).reshape(c.height, c.width, 4)
        d = np.asarray(depth_buf, dtype=np.float32).reshape(c.height, c.width)
        depth = (c.far * c.near / (c.far - (c.far - c.near) * d)).astype(np.float32)
        if not self._ground_visual:
            self._draw_ground(rgba, depth, depth > c.far * 0.999, pos, rot)
        rgb = rgba[:, :, :3].copy()
        if sensed:
            depth = self.realism.depth_image(depth, rgb)
            rgb = self.realism.colour_image(rgb)
        return rgb, depth

    def _cull_links(self, robot: str, pos: np.ndarray, rot: np.ndarray) -> list[int]:
        """Make the links of ``robot`` that lie outside the camera's view invisible for one
        frame (alpha 0: TinyRenderer then skips their triangles) and return them.

        A wrist camera never sees most of its own arm, yet TinyRenderer transforms and clips
        every triangle of it: the xArm6's and the Panda's meshes cost 20-30 ms a frame. A link
        is left out when its bounding box (the collision shapes', grown by
        :data:`CULL_MARGIN` for visual shapes that stick out) lies wholly beyond one side of
        the view frustum, so the image is the same. pos (3,) m, rot (3, 3): the camera's
        optical frame in the world.
        """
        if not self._cull_enabled or robot != 'user':
            return []
        body = self._robots[robot].body
        p = self._p
        links = self._visual_links
        boxes = np.array([p.getAABB(body, link) for link in links])          # (L, 2, 3) m
        boxes[:, 0] -= CULL_MARGIN
        boxes[:, 1] += CULL_MARGIN
        corners = boxes[:, _BOX_CORNERS, _XYZ]                                # (L, 8, 3)
        seen = _boxes_in_view((corners - pos) @ rot, self.camera.near, self._cull_tan)
        culled = [link for link, s in zip(links, seen, strict=True) if not s]
        for link in culled:
            p.changeVisualShape(body, link, rgbaColor=[1.0, 1.0, 1.0, 0.0])
        return culled

    def _uncull(self, robot: str, culled: list[int]) -> None:
        """Give the links :meth:`_cull_links` hid their colours back (each visual shape's)."""
        body = self._robots[robot].body
        for link in culled:
            for k, colour in enumerate(self._visual_colours[link]):
                self._p.changeVisualShape(body, link, shapeIndex=k, rgbaColor=colour)

    def _draw_ground(self, rgba: np.ndarray, depth: np.ndarray, empty: np.ndarray,
                     pos: np.ndarray, rot: np.ndarray) -> None:
        """Fill pixels that hit nothing with the ground plane z = 0 (exact ray-plane depth).

        rgba: (H, W, 4) uint8, C-contiguous; depth: (H, W) float32 m; empty: (H, W) bool.
        """
        if self._rays is None:
            k, w, h = self.camera_intrinsics()
            u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
            # optical-frame ray of each pixel with depth 1: (x, y, 1)
            self._rays = np.stack([(u - k[0, 2]) / k[0, 0],
                                   (v - k[1, 2]) / k[1, 1]]).astype(np.float32)
            colour = np.array([*self._ground_colour(), 255], dtype=np.uint8)
            self._ground_rgba = colour.view(np.uint32)[0]
        # world z component of each ray, then the depth at which it meets z = 0
        r = rot[2].astype(np.float32)
        rz = self._rays[0] * r[0] + self._rays[1] * r[1] + r[2]
        with np.errstate(divide='ignore', invalid='ignore'):
            t = np.float32(-pos[2]) / rz
        hit = empty & (rz < 0) & (t <= self.camera.far)
        np.copyto(depth, t, where=hit)
        # one 32-bit word per pixel: a masked fill instead of a per-channel scatter
        np.copyto(rgba.view(np.uint32).reshape(hit.shape), self._ground_rgba, where=hit)

    def render_scene(self, width: int = 320, height: int = 240,
                     eye: tuple[float, float, float] = SCENE_EYE,
                     target: tuple[float, float, float] = SCENE_TARGET,
                     fov_deg: float = 50.0) -> np.ndarray:
        """Render a third-person view of the scene for people (the participant's screen).

        Both arms are drawn; the training robot (when loaded) is blended at 50 % over what is
        behind it, so it looks green and semi-transparent (TinyRenderer ignores alpha, so the
        view is rendered twice: without and with the training robot). Pixels that hit nothing
        show the ground plane (z = 0) or, above the horizon, a plain sky.

        Parameters
        ----------
        width, height : int
            Image size (px), 8..4096.
        eye, target : (x, y, z)
            Camera position and the point it looks at (m, world frame; z up).
        fov_deg : float
            Vertical field of view (deg).

        Returns
        -------
        rgb : ndarray of uint8, shape (height, width, 3)
        """
        for name, value in (('width', width), ('height', height)):
            if not isinstance(value, (int, np.integer)) or not 8 <= value <= 4096:
                msg = (f'Scene camera {name} must be an integer number of pixels in 8..4096, got '
                       f'{value!r}; use e.g. 320x240.')
                raise SimError(msg)
        p = self._p
        near, far = 0.05, 6.0
        view = p.computeViewMatrix(list(eye), list(target), [0.0, 0.0, 1.0])
        proj = p.computeProjectionMatrixFOV(fov_deg, width / height, near, far)
        kw = {'renderer': self._renderer, 'shadow': 0, **_LIGHT}
        ghost = self._robots.get('trainer')
        hidden = self._hide_other_robots('user') if ghost is not None else []
        _, _, rgba, depth_buf, _ = p.getCameraImage(width, height, view, proj,
                                                    flags=pb.ER_NO_SEGMENTATION_MASK, **kw)
        self._unhide(hidden)
        rgb = np.array(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
        empty = np.asarray(depth_buf, dtype=np.float32).reshape(height, width) > 0.9999
        self._scene_background(rgb, empty, np.asarray(eye, float), np.asarray(target, float),
                               fov_deg)
        if ghost is not None:
            _, _, rgba2, _, seg = p.getCameraImage(width, height, view, proj, **kw)
            seg = np.asarray(seg, dtype=np.int64).reshape(height, width)
            mask = (seg >= 0) & ((seg & ((1 << 24) - 1)) == ghost.body)
            over = np.asarray(rgba2, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
            rgb[mask] = ((rgb[mask].astype(np.uint16) + over[mask]) // 2).astype(np.uint8)
        return rgb

    def _scene_background(self, rgb: np.ndarray, empty: np.ndarray, eye: np.ndarray,
                          target: np.ndarray, fov_deg: float) -> None:
        """Paint ``empty`` pixels of a scene view (rgb (H, W, 3) uint8) as ground or sky."""
        h, w = empty.shape
        forward = target - eye
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        f = h / 2.0 / math.tan(math.radians(fov_deg) / 2.0)
        u = (np.arange(w) - (w - 1) / 2.0) / f
        v = (np.arange(h) - (h - 1) / 2.0) / f
        # world z of the ray through each pixel (image v grows downwards)
        rz = forward[2] + u[None, :] * right[2] - v[:, None] * up[2]
        ground = empty & (rz < 0)
        rgb[ground] = np.asarray(GROUND_RGBA[:3]) * 255 * 0.85
        rgb[empty & ~ground] = SKY_RGB

    def _hide_other_robots(self, robot: str) -> list[tuple[int, tuple, tuple]]:
        # the trainer's ghost arm is seen by people, not by the user's camera: park it below
        # the ground while rendering (it collides with nothing, so physics is unaffected)
        hidden = []
        for name, r in self._robots.items():
            if name != robot and name == 'trainer':
                # PyBullet's base pose is the base's inertial frame, not its URDF link frame:
                # put back exactly what was read (restoring [0, 0, 0] sank the ghost 5 cm)
                pos, orn = self._p.getBasePositionAndOrientation(r.body)
                self._p.resetBasePositionAndOrientation(r.body, [0, 0, -5.0], [0, 0, 0, 1])
                hidden.append((r.body, pos, orn))
        return hidden

    def _unhide(self, hidden: list[tuple[int, tuple, tuple]]) -> None:
        for body, pos, orn in hidden:
            self._p.resetBasePositionAndOrientation(body, pos, orn)

    # ------------------------------------------------------------------ kinematics
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

    # ------------------------------------------------------------------ lifecycle
    def close(self) -> None:
        """Disconnect from PyBullet (the object is unusable afterwards)."""
        for client in (self._p, self._kin):
            with contextlib.suppress(pb.error):
                client.disconnect()

    def __enter__(self) -> Simulation:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: the 8 corners of a box (lower, upper) as indices into its (2, 3) bounds, and the 12 edges
#: between corners numbered by bits (x: 4, y: 2, z: 1)
_BOX_CORNERS = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)])
_XYZ = np.arange(3)
_BOX_EDGES = np.array([(i, i | bit) for i in range(8) for bit in (1, 2, 4) if not i & bit])


def _boxes_in_view(cam: np.ndarray, near: float, tan: tuple[float, float]) -> np.ndarray:
    """Whether each box, corners ``cam`` (L, 8, 3) m in a camera's optical frame (z forward),
    may show in its image: the part of the box beyond the near plane ``near`` m, projected,
    meets the image's rectangle of half-widths ``tan`` (x, y). Conservative (the projection's
    bounding rectangle stands for the projection). Returns (L,) bool."""
    z = cam[..., 2]
    ahead = z > near                                                       # (L, 8)
    a, b = cam[:, _BOX_EDGES[:, 0]], cam[:, _BOX_EDGES[:, 1]]              # (L, 12, 3)
    cross = ahead[:, _BOX_EDGES[:, 0]] != ahead[:, _BOX_EDGES[:, 1]]       # (L, 12)
    dz = b[..., 2] - a[..., 2]
    t = np.where(cross, (near - a[..., 2]) / np.where(cross, dz, 1.0), 0.0)
    pts = np.concatenate([cam, a + t[..., None] * (b - a)], axis=1)        # (L, 20, 3)
    valid = np.concatenate([ahead, cross], axis=1)
    zs = np.where(valid, pts[..., 2], 1.0)
    u, v = pts[..., 0] / zs, pts[..., 1] / zs
    inf = np.inf
    return (ahead.any(axis=1)
            & (np.where(valid, u, inf).min(axis=1) <= tan[0])
            & (np.where(valid, u, -inf).max(axis=1) >= -tan[0])
            & (np.where(valid, v, inf).min(axis=1) <= tan[1])
            & (np.where(valid, v, -inf).max(axis=1) >= -tan[1]))


def _in_link(pos: np.ndarray, orn: np.ndarray, frame: LinkFrame) -> tuple[np.ndarray, np.ndarray]:
    """World pose (position (3,) m, quaternion xyzw (4,)) of ``frame`` given its link's."""
    if not any(frame.xyz) and not any(frame.rpy):
        return pos, orn
    fpos, forn = pb.multiplyTransforms(pos.tolist(), orn.tolist(), list(frame.xyz),
                                       list(pb.getQuaternionFromEuler(frame.rpy)))
    return np.array(fpos), np.array(forn)


__all__ = ['HOME_POSE', 'CameraConfig', 'SceneObject', 'Simulation', 'top_down_quat']
