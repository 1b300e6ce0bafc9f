"""PyBullet simulator node: the arm contract of a ros2_control forward velocity controller plus an
RGB-D camera driver, served by :class:`~mindgrasp_sim.simulation.Simulation`.

    python -m mindgrasp_sim.sim_node --ros-args -p scene:=random_locations -p seed:=3
    python -m mindgrasp_sim.sim_node --ros-args -p time_mode:=fast -p sim_duration:=60.0
    python -m mindgrasp_sim.sim_node --ros-args \
        --params-file config/param/sim.yaml

Subscribes ``/arm_controller/commands`` (std_msgs/Float64MultiArray, per arm joint, rad/s;
older than ``command_timeout`` s means zero; clipped to the velocity limits of the loaded URDF;
NaN/inf or a wrong length is refused and holds the arm until no refused command came for
``bad_command_hold`` s; one warning per burst of bad commands), and, with the same timeout,
limits and refusals, ``/arm_controller/joint_trajectory`` (trajectory_msgs/JointTrajectory, as a
JointTrajectoryController) and ``/servo_node/delta_twist_cmds`` (geometry_msgs/TwistStamped, as
MoveIt Servo, after ``/servo_node/switch_command_type``; see
:mod:`mindgrasp_sim.command_inputs`), ``/gripper_controller/commands``
(Float64MultiArray: [closure] 0 open .. 1 closed, or [thumb, left, right]) and ``/task/target``.
Publishes ``/joint_states`` (the arm joints), ``/gripper/joint_states`` (3 fingers: angles, efforts
in N m), ``/gripper/contacts`` (std_msgs/UInt8MultiArray, 1 = finger touches an object; with
realism, any surface), ``/ee_pose``
(geometry_msgs/PoseStamped, TCP in ``world``), ``/camera/color/image_raw`` (rgb8),
``/camera/depth/image_raw`` (32FC1, m), ``/camera/color/camera_info``,
``/camera/depth/camera_info``, ``/sim/objects`` (visualization_msgs/MarkerArray),
``/scene/image_raw`` (rgb8, a third-person view of both robots for the participant's display;
``scene_camera_rate`` > 0), ``/task/result`` (mindgrasp_msgs/GraspResult) and ``/sim/status``
(diagnostic_msgs/DiagnosticArray: scene, simulated time, real-time factor, collisions). With
``trainer_robot:=true`` the training robot has the same arm topics
under ``/trainer_robot/``.
As robot_state_publisher would for a real arm: ``/robot_description`` (std_msgs/String, the URDF,
transient local), ``/tf_static`` (``world`` -> ``base_link`` and the URDF's fixed joints: camera
optical frame, TCP) and ``/tf`` (the URDF's moving joints, arm and fingers, from the published
joint states, at most ``tf_publish_frequency`` Hz as robot_state_publisher's
``publish_frequency``, 20 Hz by default; with no subscriber the tree is not computed); camera
topics carry the frame
``camera_color_optical_frame`` of that tree, and the objects are the markers on ``/sim/objects``
(in ``world``).
Services ``/sim/reset`` (ResetSim), ``/sim/load_scene`` (LoadScene) and, in lock-step mode,
``/sim/step`` (Step).

Realism (``realism``: ``none`` (default), ``default`` or a profile YAML path; ``realism_seed``):
the camera images, joint states and finger readings carry the sensor noise and physical spread
of :mod:`mindgrasp_sim.realism`, the same in every time mode.

Time modes (``time_mode``): ``realtime`` follows the node's clock (the wall clock, or /clock with
``use_sim_time``); ``fast`` steps as fast as it can and publishes ``/clock`` (run the other nodes
with ``use_sim_time:=true``); ``lockstep`` advances only on ``/sim/step`` and publishes ``/clock``.
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from mindgrasp_ros.interfaces.builtin_interfaces.msg import Time as TimeMsg
from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray
from mindgrasp_ros.interfaces.geometry_msgs.msg import PoseStamped
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import GraspResult, TaskTarget
from mindgrasp_ros.interfaces.mindgrasp_msgs.srv import LoadScene, ResetSim, Step
from mindgrasp_ros.interfaces.rosgraph_msgs.msg import Clock
from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, Image, JointState
from mindgrasp_ros.interfaces.std_msgs.msg import (
    Float64MultiArray,
    Header,
    String,
    UInt8MultiArray,
)
from mindgrasp_ros.interfaces.tf2_msgs.msg import TFMessage
from mindgrasp_ros.interfaces.visualization_msgs.msg import MarkerArray
from scipy.spatial.transform import Rotation

from mindgrasp_ros import rclpy
from mindgrasp_ros.graph_check import declare_graph_check, refuse_second_graph
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import (
    ARM_COMMANDS,
    CLOCK,
    COLOR_IMAGE,
    COLOR_INFO,
    DEPTH_IMAGE,
    DEPTH_INFO,
    EE_POSE,
    GRIPPER_COMMANDS,
    GRIPPER_CONTACTS,
    GRIPPER_JOINT_STATES,
    JOINT_STATES,
    ROBOT_DESCRIPTION,
    SCENE_IMAGE,
    SIM_OBJECTS,
    SIM_STATUS,
    TASK_RESULT,
    TASK_TARGET,
    TF,
    TF_STATIC,
    TRAINER_ROBOT,
)
from mindgrasp_sim import messages as msgs
from mindgrasp_sim.camera import CameraConfig
from mindgrasp_sim.command_inputs import ArmCommandInputs
from mindgrasp_sim.control import CommandBursts, CommandGate, gripper_closure, validate_velocities
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.params import SimParams
from mindgrasp_sim.simulation import Simulation
from mindgrasp_sim.task import TaskMonitor
from mindgrasp_sim.tf_tree import TfTree, Transform

#: realtime: a lag skipped beyond this (s) is a stall and is warned (a smaller one, beyond
#: ``max_catch_up``, is a busy machine: the status' real_time_factor shows it)
STALL_WARNING = 0.25
#: realtime: a callback this many joint-state periods behind is a catch-up (newest state only)
CATCH_UP_PERIODS = 5


@dataclass
class _RobotIO:
    """Topics and command state of one simulated arm."""

    name: str
    prefix: str
    gate: CommandGate
    bursts: CommandBursts
    applied: np.ndarray           #: the velocities in force (n_joints,) rad/s
    pubs: dict = field(default_factory=dict)
    inputs: object = None     #: its ArmCommandInputs (trajectory, servo twist)


class SimNode(rclpy.node.Node):
    """Thin ROS layer over :class:`Simulation` (see the module docstring for the contract)."""

    node_traits = NodeTraits(name='sim', seed_parameters=('seed', 'realism_seed'),
                             periodic={JOINT_STATES.name: ('joint_state_rate', 'rate'),
                                       COLOR_IMAGE.name: ('camera_rate', 'rate')})

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.params = declare_params(self, SimParams)
        p = self.params
        started, graph_check_wait = time.monotonic(), declare_graph_check(self)
        try:
            gui = bool(p.gui)
            if gui and not os.environ.get('DISPLAY') and sys.platform.startswith('linux'):
                self.get_logger().warning(
                    'gui:=true needs a display (DISPLAY is not set); running headless instead.')
                gui = False
            self.sim = Simulation(
                scene=p.scene, seed=int(p.seed),
                camera=CameraConfig(int(p.camera_width), int(p.camera_height),
                                    float(p.camera_rate), float(p.camera_fov_deg),
                                    renderer=str(p.camera_renderer)),
                physics_hz=float(p.physics_hz),
                solver_iterations=int(p.solver_iterations),
                trainer_robot=bool(p.trainer_robot), gui=gui,
                n_objects=None if int(p.n_objects) < 0 else int(p.n_objects),
                realism=str(p.realism), realism_seed=int(p.realism_seed),
                robot=str(p.robot))
        except SimError as err:
            self.get_logger().error(str(err))
            raise
        self.mode = p.time_mode
        self.done = rclpy.task.Future()
        self.monitor = TaskMonitor(success_height=float(p.success_height))
        self.monitor.new_trial(0.0)
        self.desired = ''
        self.task_trial = 0       # /task/target's trial: the number /task/result reports
        self.total_steps = 0
        self.js_every = self.sim.physics_hz / float(p.joint_state_rate)
        # /tf at most at tf_publish_frequency, as robot_state_publisher's publish_frequency
        self.tf_every = self.sim.physics_hz / min(float(p.tf_publish_frequency),
                                                  float(p.joint_state_rate))
        self._next_tf_step = 0.0
        self.cam_every = self.sim.physics_hz / self.sim.camera.rate_hz
        self.obj_every = self.sim.physics_hz / float(p.objects_rate)
        self.task_every = max(1, round(self.sim.physics_hz / 20.0))
        self.status_every = max(1, round(self.sim.physics_hz))     # 1 s of simulated time
        scene_rate = float(p.scene_camera_rate)
        self.scene_every = self.sim.physics_hz / scene_rate if scene_rate > 0 else math.inf
        # the scene camera's first frame is due at once; never when it is off
        self._next = {'js': 0.0, 'cam': 0.0, 'obj': 0.0,
                      'scene': 0.0 if scene_rate > 0 else math.inf}
        self._collisions: list[str] = []
        self._last_state_step = -1
        self._wall_start = time.monotonic()
        self._cpu_start = time.process_time()

        self.robots: dict[str, _RobotIO] = {}
        for name in self.sim.robots:
            prefix = '' if name == 'user' else TRAINER_ROBOT
            io = _RobotIO(name, prefix,
                          CommandGate(float(p.command_timeout), self.sim.n_joints),
                          CommandBursts(float(p.bad_command_hold)), np.zeros(self.sim.n_joints))
            js, fingers, contacts, ee, arm, gripper = (t.in_namespace(prefix) for t in (
                JOINT_STATES, GRIPPER_JOINT_STATES, GRIPPER_CONTACTS, EE_POSE, ARM_COMMANDS,
                GRIPPER_COMMANDS))
            io.pubs['js'] = self.create_publisher(JointState, js.name, js.qos)
            io.pubs['gripper'] = self.create_publisher(JointState, fingers.name, fingers.qos)
            io.pubs['contacts'] = self.create_publisher(UInt8MultiArray, contacts.name,
                                                        contacts.qos)
            io.pubs['ee'] = self.create_publisher(PoseStamped, ee.name, ee.qos)
            self.create_subscription(Float64MultiArray, arm.name,
                                     lambda msg, io=io: self.arm_command_callback(msg, io), arm.qos)
            self.create_subscription(
                Float64MultiArray, gripper.name,
                lambda msg, io=io: self.gripper_command_callback(msg, io), gripper.qos)
            io.inputs = ArmCommandInputs(self, io)    # trajectory and MoveIt Servo twist
            self.robots[name] = io
        self.color_pub = self.create_publisher(Image, COLOR_IMAGE.name, COLOR_IMAGE.qos)
        self.depth_pub = self.create_publisher(Image, DEPTH_IMAGE.name, DEPTH_IMAGE.qos)
        self.info_pub = self.create_publisher(CameraInfo, COLOR_INFO.name, COLOR_INFO.qos)
        self.depth_info_pub = self.create_publisher(CameraInfo, DEPTH_INFO.name, DEPTH_INFO.qos)
        self.scene_pub = (self.create_publisher(Image, SCENE_IMAGE.name, SCENE_IMAGE.qos)
                          if self.scene_every < math.inf else None)
        self.objects_pub = self.create_publisher(MarkerArray, SIM_OBJECTS.name, SIM_OBJECTS.qos)
        self.result_pub = self.create_publisher(GraspResult, TASK_RESULT.name, TASK_RESULT.qos)
        self.status_pub = self.create_publisher(DiagnosticArray, SIM_STATUS.name, SIM_STATUS.qos)
        self._status_mark = (time.monotonic(), 0)
        self.clock_pub = None
        if self.mode in ('fast', 'lockstep'):
            self.clock_pub = self.create_publisher(Clock, CLOCK.name, CLOCK.qos)
        self.create_subscription(TaskTarget, TASK_TARGET.name, self.target_callback,
                                 TASK_TARGET.qos)
        self.create_service(ResetSim, '/sim/reset', self.reset_callback)
        self.create_service(LoadScene, '/sim/load_scene', self.load_scene_callback)
        self.create_service(Step, '/sim/step', self.step_callback)
        self._t0 = self._clock_s() if self.mode == 'realtime' else 0.0
        self._clock_started = False      # realtime: the clock starts at the first callback
        self._set_t0(self._t0)
        if self.mode == 'realtime':
            self.create_timer(1.0 / float(p.joint_state_rate), self.realtime_callback)
        elif self.mode == 'fast':
            # always ready; each call steps for ~2 ms of wall time, then lets the executor take
            # commands and requests (works under main() and in a composed process alike)
            self.create_timer(0.0, self.fast_callback)
        # a second /sim (another graph on this domain): refused before the first message
        refuse_second_graph(self, SimError, started=started, wait=graph_check_wait,
                            own_publishers={SIM_STATUS.name: 1})
        end_after(self, p.duration)
        self._publish_robot_description()
        self.publish_all()
        robots = ' and the training robot' if 'trainer' in self.robots else ''
        if self.sim.realism.enabled:
            robots += (f", realism profile '{self.sim.realism.profile.name}' (seed "
                       f'{self.sim.realism.seed})')
        self.get_logger().info(
            f"Simulating scene '{self.sim.scene.name}' ({len(self.sim.objects())} objects) with "
            f"the robot '{self.sim.robot.name}'{robots}"
            f' at {self.sim.physics_hz:.0f} Hz physics, camera {self.sim.camera.width}x'
            f'{self.sim.camera.height} px at {self.sim.camera.rate_hz:g} Hz, {self.mode} mode.')

    # ------------------------------------------------------------------ time
    def _clock_s(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _set_t0(self, t0: float) -> None:
        self._t0 = t0
        self._t0_ns = round(t0 * 1e9)
        self._dt_ns = round(self.sim.dt * 1e9)
        self._stamp_cache: tuple[int, TimeMsg | None] = (-1, None)

    def _skip_steps(self, n: int) -> float:
        """Move the start time on by ``n`` whole physics steps (a stall skipped); the seconds
        skipped."""
        self._t0 += n * self.sim.dt
        self._t0_ns += n * self._dt_ns
        self._stamp_cache = (-1, None)
        return n * self.sim.dt

    def sim_now(self) -> float:
        """Node time (s): start time plus simulated time since start (never goes back)."""
        return self._t0 + self.total_steps * self.sim.dt

    def _stamp(self) -> TimeMsg:
        # integer nanoseconds: start time plus whole physics steps (no float drift)
        if self._stamp_cache[0] != self.total_steps:
            ns = self._t0_ns + self.total_steps * self._dt_ns
            self._stamp_cache = (self.total_steps, msgs.stamp(ns))
        return self._stamp_cache[1]

    def advance(self, n_steps: int, *, newest_only: bool = False) -> None:
        """Step the physics ``n_steps`` times, publishing whatever falls due.

        ``newest_only`` (a real-time catch-up): joint states and camera frames that fall due
        before the last step are not sent; the newest of each goes out once the steps are done.
        A driver sends the arm's state as it is now, not a backlog, and the backlog cost a
        starved simulator the time it was catching up with (ten joint-state sets for 0.1 s of
        lag, each waking the controller for a state it could only judge stale)."""
        sim = self.sim
        n_steps = int(n_steps)
        js_held = cam_held = False     # fell due, not yet sent (newest_only)
        for i in range(n_steps):
            now = self.sim_now()
            for io in self.robots.values():
                v = io.gate.current(now)
                # the gate hands out a new array only for a new command (or the timeout)
                if v is not io.applied:
                    if (v != io.applied).any():     # cheaper than np.array_equal
                        sim.set_joint_velocities(v, robot=io.name)
                    io.applied = v
            sim.step()
            self.total_steps += 1
            k = self.total_steps + 1e-6    # schedules are fractional step counts
            last = not newest_only or i == n_steps - 1
            if k >= self._next['js']:
                self._next['js'] += self.js_every
                js_held = True
            if k >= self._next['cam']:
                self._next['cam'] += self.cam_every
                cam_held = True
            if last and js_held:
                js_held = False
                self.publish_states()
            if last and cam_held:
                cam_held = False
                self.publish_camera()
            if k >= self._next['scene']:
                self._next['scene'] += self.scene_every
                self.publish_scene()
            if k >= self._next['obj']:
                self._next['obj'] += self.obj_every
                self.publish_objects()
            if self.total_steps % self.task_every == 0:
                self.check_task()
            if self.total_steps % self.status_every == 0:
                self.publish_status()
        if self.clock_pub is not None:
            self.clock_pub.publish(Clock(clock=self._stamp()))
        limit = float(self.params.sim_duration)
        if limit > 0 and self.total_steps * sim.dt >= limit:
            self._finish()

    def realtime_callback(self) -> None:
        """Catch up with the node's clock (wall, or /clock with use_sim_time).

        The simulated clock starts at the first call: the time the node took to build the
        scene, publish its first frame and start spinning (a loaded machine takes seconds) is
        no lag, and the start says nothing about it. A lag beyond ``max_catch_up`` later on
        (a stall) is skipped with a warning."""
        if self.total_steps == 0 and not self._clock_started:
            self._clock_started = True
            start = self._clock_s()
            for io in self.robots.values():
                io.gate.shift(start - self._t0)     # commands that came before the start
            self._set_t0(start)
            return
        due = self._clock_s() - self.sim_now()
        cap = float(self.params.max_catch_up)
        if due > cap:
            # the machine is too slow (or the clock jumped): drop the lag instead of racing,
            # so that the joint states a controller judges are never much older than the
            # clock (a busy 2-core machine keeps a sim 0.1-0.3 s behind: with 0.25 s kept, its
            # states sat at the controller's 0.3 s watchdog and latched stop after stop)
            if due > STALL_WARNING:
                self.get_logger().warning(
                    f'The simulation is {due:.2f} s behind its clock; skipping ahead. Lower '
                    'camera_width/height or camera_rate, or use time_mode:=fast.',
                    throttle_duration_sec=5.0)
            # a whole number of physics steps, so that every stamp stays the start time plus
            # whole steps (a consumer may count steps between two states)
            skip = self._skip_steps(math.floor((due - cap) * self.sim.physics_hz))
            for io in self.robots.values():
                # commands that arrived during the lag were stamped before the skip; without
                # this they would all be stale after it, and an overloaded sim ignores its arms
                io.gate.shift(skip)
            due -= skip
        n = int(due * self.sim.physics_hz)
        if n > 0:
            # a catch-up (more than five joint-state periods behind) sends only its newest
            # state; a punctual callback publishes each state at its own step, as a lock-step
            # host's (one 20 ms control period a step) always does
            catch_up = due > CATCH_UP_PERIODS / float(self.params.joint_state_rate)
            self.advance(n, newest_only=catch_up)

    def fast_iteration(self) -> None:
        """One iteration of fast mode: the physics steps up to the next joint state."""
        n = max(1, math.ceil(self._next['js'] - self.total_steps))
        self.advance(n)

    def fast_callback(self) -> None:
        """Fast mode: step as fast as possible for about 2 ms of wall time."""
        end = time.monotonic() + 0.002
        while not self.done.done() and time.monotonic() < end:
            self.fast_iteration()

    # ------------------------------------------------------------------ commands
    def arm_command_callback(self, msg: Float64MultiArray, io: _RobotIO) -> None:
        """Joint velocities (rad/s) on /arm_controller/commands."""
        self.accept_arm_command(lambda: validate_velocities(msg.data, io.gate.n_joints), io,
                                f'{io.prefix}{ARM_COMMANDS.name}')

    def accept_arm_command(self, velocities: Callable[[], np.ndarray], io: _RobotIO,
                           topic: str) -> None:
        """The joint velocities (n_joints,) rad/s that ``velocities()`` reads from a command of any
        interface. A refused command (``velocities()`` raises SimError) stops the arm, which then
        holds until the commands were valid for ``bad_command_hold`` s; a command beyond the
        URDF's velocity limits is clipped to them. One warning per burst of each."""
        now = self.sim_now()
        hold = io.bursts.hold
        try:
            v = velocities()
        except SimError as err:
            io.gate.clear()
            if io.bursts.bad('refused', now):
                self.get_logger().warning(
                    f'Rejected {topic}: {err} The arm holds still until the commands are valid '
                    f'for {hold:.1f} s (one warning per burst).')
            return
        if io.bursts.holding('refused', now):
            return                  # a burst of refused commands: the arm keeps holding
        if io.bursts.count.pop('refused', 0):
            self.get_logger().info(f'{topic} valid for {hold:.1f} s again; the arm follows them.')
        limits = self.sim.max_velocity
        if (np.abs(v) > limits).any() and io.bursts.bad('clipped', now):
            self.get_logger().warning(
                f'Clipped {topic} {np.round(v, 3).tolist()} rad/s to the velocity limits of the '
                f'URDF {limits.tolist()} rad/s (one warning per burst); command at most those.')
        io.gate.command(v, now)

    def gripper_command_callback(self, msg: Float64MultiArray, io: _RobotIO) -> None:
        """Gripper closure target(s)."""
        try:
            self.sim.set_gripper(gripper_closure(msg.data), robot=io.name)
        except SimError as err:
            if io.bursts.bad('gripper', self.sim_now()):
                self.get_logger().warning(f'Rejected {io.prefix}/gripper_controller/commands: '
                                          f'{err} (one warning per burst)')

    def target_callback(self, msg: TaskTarget) -> None:
        self.desired = f'{msg.colour} {msg.shape}'.strip()
        self.task_trial = int(msg.trial)

    # ------------------------------------------------------------------ services
    def _after_reset(self) -> None:
        for io in self.robots.values():
            io.gate.clear()
            io.applied = np.zeros(self.sim.n_joints)
        self.monitor.new_trial(self.sim.time)
        self.publish_all()

    def reset_callback(self, request: ResetSim.Request, response: ResetSim.Response
                       ) -> ResetSim.Response:
        try:
            seed = None if int(request.seed) < 0 else int(request.seed)
            self.sim.reset(new_random_draw=bool(request.new_random_draw), seed=seed)
        except SimError as err:
            response.success, response.message = False, str(err)
            self.get_logger().error(f'/sim/reset failed: {err}')
            return response
        self._after_reset()
        response.success = True
        response.message = (f'Reset: robots home, {len(self.sim.objects())} objects of '
                            f"'{self.sim.scene.name}' (layout seed {self.sim.layout_seed}).")
        self.get_logger().info(response.message)
        return response

    def load_scene_callback(self, request: LoadScene.Request, response: LoadScene.Response
                            ) -> LoadScene.Response:
        try:
            seed = None if int(request.seed) < 0 else int(request.seed)
            self.sim.load_scene(request.scene, seed=seed)
        except SimError as err:
            response.success, response.message = False, str(err)
            self.get_logger().error(f'/sim/load_scene failed: {err}')
            return response
        self._after_reset()
        response.success = True
        response.message = f"Loaded scene '{self.sim.scene.name}' with " \
                           f'{len(self.sim.objects())} objects.'
        self.get_logger().info(response.message)
        return response

    def step_callback(self, request: Step.Request, response: Step.Response) -> Step.Response:
        if self.mode != 'lockstep':
            self.get_logger().warning(
                f'/sim/step is served in time_mode lockstep only (this node runs {self.mode}); '
                'start the node with -p time_mode:=lockstep.')
            response.success = False
        else:
            self.advance(int(request.steps))
            if self._last_state_step != self.total_steps:
                self.publish_states()    # the caller sees the state at the returned time
            response.success = True
        response.sim_time = self._stamp()
        return response

    # ------------------------------------------------------------------ publishing
    def _header(self, frame_id: str = '') -> Header:
        return msgs.header(self._stamp(), frame_id)

    def _publish_robot_description(self) -> None:
        """/robot_description and /tf_static once (latched), and the /tf publisher, with the QoS
        of robot_state_publisher and tf2_ros' broadcasters (mindgrasp_ros.topics)."""
        urdf = self.sim.urdf.read_text(encoding='utf-8')
        self.tf_tree = TfTree(urdf)
        self.create_publisher(String, ROBOT_DESCRIPTION.name, ROBOT_DESCRIPTION.qos).publish(
            String(data=urdf))
        # the arm stands at the world origin (the simulation loads it there); a URDF whose root
        # is that frame already (the xArm's 'world') gets no transform: tf2 refuses a frame that
        # is its own parent
        base = [] if self.tf_tree.root == self.params.frame_id else [
            Transform(self.params.frame_id, self.tf_tree.root, np.zeros(3),
                      np.array([0.0, 0.0, 0.0, 1.0]))]
        self.tf_static_pub = self.create_publisher(TFMessage, TF_STATIC.name, TF_STATIC.qos)
        self.tf_static_pub.publish(msgs.tf_message(
            self._stamp(), [*base, *self.tf_tree.static_transforms(), *self._mount_transforms()]))
        self.tf_pub = self.create_publisher(TFMessage, TF.name, TF.qos)

    def _mount_transforms(self) -> list[Transform]:
        """The robot description's frames the URDF lacks, as static transforms from their links:
        the camera optical frame (the camera topics' frame) on a wrist-camera mount, the TCP."""
        robot = self.sim.robot
        out = []
        for name, frame in ((msgs.OPTICAL_FRAME, robot.camera), ('tcp', robot.tcp)):
            if name not in self.tf_tree.links:
                quat = Rotation.from_euler('xyz', frame.rpy).as_quat()   # URDF rpy, xyzw
                out.append(Transform(frame.link, name, np.array(frame.xyz), quat))
        return out

    def publish_all(self) -> None:
        self.publish_states()
        self.publish_camera()
        self.publish_objects()
        if self.clock_pub is not None:
            self.clock_pub.publish(Clock(clock=self._stamp()))

    def publish_states(self) -> None:
        """Joint states, finger states and contacts, and the TCP pose of every robot."""
        self._last_state_step = self.total_steps
        sim = self.sim
        hdr, world = self._header(), self._header(self.params.frame_id)
        for io in self.robots.values():
            q, v = sim.joint_readings(io.name)     # encoder readings (noisy with realism)
            io.pubs['js'].publish(msgs.joint_state(hdr, sim.joint_names, q, v,
                                                   sim.joint_efforts(io.name)))
            state = sim.gripper_state(io.name)
            io.pubs['gripper'].publish(msgs.joint_state(hdr, sim.finger_names,
                                                        state['positions'],
                                                        effort=state['efforts']))
            io.pubs['contacts'].publish(UInt8MultiArray(
                data=state['contacts'].astype(np.uint8)))
            io.pubs['ee'].publish(msgs.pose_stamped(world, *sim.ee_pose(io.name)))
            if io.name == 'user' and self.total_steps >= self._next_tf_step:
                # the tree robot_state_publisher makes of these joint states
                self._next_tf_step = self.total_steps + self.tf_every - 1e-6
                # nobody listening (lock-step experiments): no tree to build
                if self.tf_pub.get_subscription_count():
                    positions = dict(zip(sim.joint_names, q, strict=True))
                    positions.update(zip(sim.finger_names, state['positions'], strict=True))
                    self.tf_pub.publish(msgs.tf_message(hdr.stamp,
                                                        self.tf_tree.transforms(positions)))

    def publish_camera(self) -> None:
        """Colour and depth images of the user's eye-in-hand camera, with camera_info."""
        rgb, depth = self.sim.render_camera()
        hdr = self._header(msgs.OPTICAL_FRAME)
        color, depth_msg = msgs.image_messages(hdr, rgb, depth)
        self.color_pub.publish(color)
        self.depth_pub.publish(depth_msg)
        k, w, h = self.sim.camera_intrinsics()
        self.info_pub.publish(msgs.camera_info(hdr, k, w, h))
        self.depth_info_pub.publish(msgs.camera_info(hdr, k, w, h))

    def publish_scene(self) -> None:
        """/scene/image_raw (rgb8): the third-person view for the participant's display."""
        rgb = self.sim.render_scene(int(self.params.scene_camera_width),
                                    int(self.params.scene_camera_height))
        self.scene_pub.publish(msgs.rgb_image(self._header('scene_camera'), rgb))

    def publish_objects(self) -> None:
        self.objects_pub.publish(msgs.object_markers(self._header(self.params.frame_id),
                                                     self.sim.objects()))

    def check_task(self) -> None:
        """Publish /task/result on a lift or a drop; report new arm collisions."""
        event = self.monitor.update(self.sim)
        if event is not None:
            result = msgs.grasp_result(self._header(self.params.frame_id), event, self.desired,
                                       self.task_trial)
            self.result_pub.publish(result)
            self.get_logger().info(
                f'Trial {result.trial}: {event.grasped_object} {event.reason} '
                f'(lift {event.lift_height:.3f} m, {event.duration:.1f} s).')
        if self.total_steps % (self.task_every * 4) == 0:
            collisions = self.sim.collisions()
            new = sorted(set(collisions) - set(self._collisions))
            self._collisions = collisions
            if new:
                self.get_logger().warning(f'Arm collision: {", ".join(new)}.')
                self.publish_status()

    def publish_status(self) -> None:
        """/sim/status: scene, simulated time, real-time factor since the last status,
        collisions (WARN while the arm touches the ground or itself)."""
        wall, steps = time.monotonic(), self.total_steps
        wall0, steps0 = self._status_mark
        self._status_mark = (wall, steps)
        rtf = (steps - steps0) * self.sim.dt / max(wall - wall0, 1e-9)
        held = self.sim.held_object()
        values = {
            'scene': self.sim.scene.name, 'layout_seed': self.sim.layout_seed,
            'time_mode': self.mode, 'sim_time_s': f'{self.sim.time:.3f}',
            'real_time_factor': f'{rtf:.2f}', 'trial': self.monitor.trial,
            'held_object': held.label if held else '',
            'collisions': ', '.join(self._collisions),
        }
        ok = not self._collisions
        text = 'running' if ok else f'arm collision: {", ".join(self._collisions)}'
        self.status_pub.publish(msgs.status(self._header(), ok, text, values))

    # ------------------------------------------------------------------ lifecycle
    @property
    def finished(self) -> bool:
        """True once ``duration`` / ``sim_duration`` is over."""
        return self.done.done()

    def _finish(self) -> None:
        if not self.done.done():
            self.done.set_result(0)

    def destroy_node(self) -> None:
        """Log the real-time factor of the run (also after Ctrl-C), close the simulation."""
        wall = time.monotonic() - self._wall_start
        simulated = self.total_steps * self.sim.dt
        cpu = time.process_time() - self._cpu_start
        if simulated > 0:
            self.get_logger().info(
                f'Simulated {simulated:.2f} s in {wall:.2f} s wall time: real-time factor '
                f'{simulated / max(wall, 1e-9):.2f}x ({simulated / max(cpu, 1e-9):.2f}x per CPU '
                'second of this process).')
        else:   # stopped before the first step: a factor of 0.00x says nothing
            self.get_logger().info(f'Stopped after {wall:.2f} s wall time, before the first '
                                   'simulation step.')
        self.sim.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the simulator until Ctrl-C, ``duration`` (s of its ROS time) or ``sim_duration``
    (simulated s)."""
    return run_node(SimNode, args, errors=(SimError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
