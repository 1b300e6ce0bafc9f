"""The simulator node composed in one process on a lock-step clock (mindgrasp_ros.graph):
a controller node grasps through the ROS topics and the node reports /task/result; two runs with
one seed give identical messages."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from mindgrasp_ros import rclpy
from mindgrasp_ros.graph.lockstep import LockstepRunner
from mindgrasp_sim.sim_node import SimNode
from mindgrasp_sim.simulation import Simulation, top_down_quat

pytestmark = pytest.mark.slow


class ScriptedController(rclpy.node.Node):
    """Drives the arm through joint waypoints with velocity commands (60 Hz), closes the
    gripper at the grasp waypoint, and records /joint_states and /task/result."""

    def __init__(self, waypoints: list[np.ndarray], grasp_index: int, max_speed: np.ndarray,
                 **kwargs) -> None:
        super().__init__('scripted_controller', **kwargs)
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import GraspResult, TaskTarget
        from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
        from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

        self.Float64MultiArray = Float64MultiArray
        self.waypoints, self.grasp_index, self.max_speed = waypoints, grasp_index, max_speed
        self.index, self.wait_until = 0, None
        self.q: np.ndarray | None = None
        self.trajectory: list[np.ndarray] = []
        self.results: list = []
        self.arm = self.create_publisher(Float64MultiArray, '/arm_controller/commands', 10)
        self.gripper = self.create_publisher(Float64MultiArray, '/gripper_controller/commands',
                                             10)
        latched = rclpy.qos.QoSProfile(
            depth=1, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
            durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_publisher(TaskTarget, '/task/target', latched).publish(
            TaskTarget(trial=7, object_id=0, colour='blue', shape='cylinder', scene='one'))
        self.create_subscription(JointState, '/joint_states', self.joints_callback, 10)
        self.create_subscription(GraspResult, '/task/result', self.results.append, 10)
        self.create_timer(1.0 / 60.0, self.control_callback)

    def joints_callback(self, msg) -> None:
        self.q = np.asarray(msg.position, dtype=float)
        self.trajectory.append(self.q)

    def now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def control_callback(self) -> None:
        if self.q is None or self.index >= len(self.waypoints):
            return
        if self.wait_until is not None:
            if self.now() < self.wait_until:
                return
            self.wait_until = None
            self.index += 1
            return
        err = self.waypoints[self.index] - self.q
        if np.max(np.abs(err)) < 0.004:
            self.arm.publish(self.Float64MultiArray(data=np.zeros(6)))
            if self.index == self.grasp_index:
                self.gripper.publish(self.Float64MultiArray(data=np.array([1.0])))
                self.wait_until = self.now() + 1.2
            else:
                self.index += 1
            return
        v = np.clip(3.0 * err, -self.max_speed, self.max_speed)
        self.arm.publish(self.Float64MultiArray(data=v))


def one_object_scene(tmp_path) -> tuple[str, dict]:
    scene = {'name': 'one', 'objects': [{'shape': 'cylinder', 'colour': 'blue', 'size': 0.05,
                                         'position': [0.42, -0.15]}]}
    path = tmp_path / 'one.yaml'
    path.write_text(yaml.safe_dump(scene))
    return str(path), scene


def plan_waypoints(scene: dict) -> tuple[list[np.ndarray], int, np.ndarray]:
    """Joint waypoints: above the object, down in 2 cm steps, then up to 0.35 m."""
    with Simulation(scene) as kin:
        obj = kin.objects()[0]
        quat = top_down_quat(math.atan2(obj.position[1], obj.position[0]))
        xy = obj.position[:2]
        heights = [0.18, 0.15, 0.12, 0.10, 0.08, 0.06, 0.04, 0.028]
        q = kin.home_pose
        waypoints = []
        for z in heights:
            q = kin.inverse_kinematics(np.array([*xy, z]), quat, seed_q=q)
            waypoints.append(q)
        grasp_index = len(waypoints) - 1
        for z in (0.08, 0.15, 0.25, 0.35):
            q = kin.inverse_kinematics(np.array([*xy, z]), quat, seed_q=q)
            waypoints.append(q)
        return waypoints, grasp_index, kin.max_velocity * 0.5


def run_grasp(scene_path: str, scene: dict, seconds: float = 16.0):
    waypoints, grasp_index, speed = plan_waypoints(scene)
    with LockstepRunner() as runner:
        sim = runner.add(SimNode, ros_args=['-p', f'scene:={scene_path}'])
        ctl = runner.add(ScriptedController, waypoints, grasp_index, speed)
        for _ in range(int(seconds * 100)):
            runner.step(0.01)
            if ctl.results and ctl.index >= len(ctl.waypoints):
                break
        held = sim.sim.held_object()
        return ctl.results, np.array(ctl.trajectory), held


def test_grasp_through_ros_topics_reports_task_result(tmp_path):
    path, scene = one_object_scene(tmp_path)
    results, trajectory, held = run_grasp(path, scene)
    assert held is not None and held.label == 'blue cylinder'
    assert len(results) == 1, [(r.success, r.reason) for r in results]
    r = results[0]
    assert r.success and r.grasped_object == 'blue cylinder'
    # the task's trial number, not the simulator's count of resets
    assert r.desired_object == 'blue cylinder' and r.trial == 7
    assert r.lift_height > 0.22 and 'lifted' in r.reason
    assert 3.0 < r.duration < 16.0
    assert len(trajectory) > 300

    results_b, trajectory_b, _ = run_grasp(path, scene)
    np.testing.assert_array_equal(trajectory, trajectory_b)
    assert results_b[0].duration == r.duration



def test_tf_tree_is_built_only_while_someone_subscribes():
    """No /tf tree is computed for nobody (lock-step experiments have no viewer); a subscriber
    that joins later gets /tf at tf_publish_frequency (20 Hz)."""
    from mindgrasp_ros.interfaces.tf2_msgs.msg import TFMessage

    with LockstepRunner() as runner:
        sim = runner.add(SimNode)
        built = []
        transforms = sim.tf_tree.transforms
        sim.tf_tree.transforms = lambda positions: built.append(1) or transforms(positions)
        for _ in range(50):
            runner.step(0.02)
        assert built == []
        listener = runner.add(rclpy.node.Node, 'tf_listener')
        received = []
        listener.create_subscription(TFMessage, '/tf', received.append, 100)
        for _ in range(50):
            runner.step(0.02)
        assert 18 <= len(received) <= 22 and len(built) == len(received)
        assert {t.child_frame_id for t in received[-1].transforms} >= {'link_1', 'finger_left'}
