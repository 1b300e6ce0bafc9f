"""The simulated world: the ground, the robots loaded from their URDF, the scene's objects,
scene loading and resets, and what touches what (held object, collisions).
:class:`~mindgrasp_sim.simulation.Simulation` inherits these methods; the attributes they use are
set by its constructor."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mindgrasp_common.robot_description import RobotDescription
from mindgrasp_common.types import SceneObject
from mindgrasp_sim.arm_control import _Robot
from mindgrasp_sim.bullet_client import _c_stdout_to_stderr
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.pybullet_quiet import BulletClient, pb
from mindgrasp_sim.realism import Realism
from mindgrasp_sim.scene import ObjectSpec, SceneSpec, load_scene

#: colours (rgba, 0..1) of the ground and of the training robot (green, semi-transparent)
GROUND_RGBA = (0.78, 0.77, 0.74, 1.0)
TRAINER_RGBA = (0.1, 0.85, 0.1, 0.35)


class WorldMixin:
    """Ground, robots, objects and resets of :class:`~mindgrasp_sim.simulation.Simulation`
    (positions in m, world frame, z up)."""

    # set by Simulation.__init__
    _p: BulletClient
    _robots: dict[str, _Robot]
    _objects: list[tuple[ObjectSpec, int]]
    _scene: SceneSpec | None
    _ground: int
    _ground_visual: bool
    _arm_idx: list[int]
    _finger_idx: list[int]
    _finger_open: np.ndarray
    _finger_links: dict[int, str]
    _base_links: set[int]
    _layout_seed: int
    _layout: list[ObjectSpec]
    _trial: int
    _step_count: int
    robot: RobotDescription
    realism: Realism
    urdf: Path
    home_pose: np.ndarray
    n_joints: int
    n_objects: int | None
    seed: int

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
