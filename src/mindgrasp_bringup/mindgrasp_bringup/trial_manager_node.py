"""Runs grasp trials: publishes the desired object, waits for the grasp, resets the scene.

    python -m mindgrasp_bringup.trial_manager_node --ros-args -p n_trials:=5 -p seed:=1

Publishes ``/task/target`` (mindgrasp_msgs/TaskTarget, transient local), reads ``/sim/objects``
(the scene), ``/task/result`` (mindgrasp_msgs/GraspResult, from the simulator) and ``/fsm/state``;
calls ``/sim/reset`` between trials. A trial ends with a result, or after ``trial_timeout``. The
node ends after ``n_trials`` (0: never) and prints the tally; the demo profile starts it.
"""

from __future__ import annotations

import time

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, GraspResult, TaskTarget
from mindgrasp_ros.interfaces.mindgrasp_msgs.srv import ResetSim
from mindgrasp_ros.interfaces.visualization_msgs.msg import MarkerArray

from mindgrasp_bringup.trials import TrialOutcome, TrialPlanner
from mindgrasp_common.markers import objects_from_markers
from mindgrasp_common.types import SceneObject
from mindgrasp_ros import rclpy


class TrialManagerNode(rclpy.node.Node):
    """Trial loop of the set-locations protocol (see module docstring)."""

    def __init__(self) -> None:
        super().__init__('trial_manager')
        self.n_trials = int(self.declare_parameter('n_trials', 0).value)
        self.trial_timeout = float(self.declare_parameter('trial_timeout', 300.0).value)
        self.settle_time = float(self.declare_parameter('settle_time', 3.0).value)
        self.scene_name = str(self.declare_parameter('scene', 'set_locations').value)
        # comma-separated labels ("red cube, blue sphere") taken in turn; empty: random draws
        targets = str(self.declare_parameter('targets', '').value)
        self.planner = TrialPlanner(seed=int(self.declare_parameter('seed', 0).value),
                                    targets=[t.strip() for t in targets.split(',') if t.strip()])
        latched = rclpy.qos.QoSProfile(depth=1,
                                       durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
        self.target_pub = self.create_publisher(TaskTarget, '/task/target', latched)
        self.create_subscription(MarkerArray, '/sim/objects', self.objects_callback, 10)
        self.create_subscription(GraspResult, '/task/result', self.result_callback, 10)
        self.create_subscription(FsmState, '/fsm/state', self.fsm_callback, latched)
        self.reset_client = self.create_client(ResetSim, '/sim/reset')
        self.scene: list[SceneObject] = []
        self.fsm_state = 0
        self.trial = 0
        self.target: SceneObject | None = None
        self.trial_start = 0.0
        self.result: GraspResult | None = None
        self.phase = 'waiting for the scene'
        self.phase_since = time.monotonic()
        self.reset_future = None
        self.done = False
        self.create_timer(0.1, self.tick)

    # ------------------------------------------------------------------ inputs
    def objects_callback(self, msg: MarkerArray) -> None:
        self.scene = objects_from_markers(msg.markers)

    def result_callback(self, msg: GraspResult) -> None:
        if self.phase == 'trial' and self.result is None:
            self.result = msg

    def fsm_callback(self, msg: FsmState) -> None:
        self.fsm_state = int(msg.state)

    # ------------------------------------------------------------------ trial loop
    def _enter(self, phase: str) -> None:
        self.phase, self.phase_since = phase, time.monotonic()

    def tick(self) -> None:
        now = time.monotonic()
        if self.phase == 'waiting for the scene':
            if self.scene:
                self._start_trial()
        elif self.phase == 'trial':
            if self.result is not None:
                self._finish(self.result.grasped_object, bool(self.result.success), False)
            elif now - self.trial_start > self.trial_timeout:
                self._finish('', False, True)
        elif self.phase == 'settling':
            # let the controller bring the arm home before the scene is reset under it
            if (self.fsm_state in (FsmState.OBJECT_SEARCH, 0)
                    and now - self.phase_since > self.settle_time) or \
                    now - self.phase_since > 30.0:
                self._reset()
        elif self.phase == 'resetting':
            if self.reset_future is not None and self.reset_future.done():
                self.reset_future = None
                self._start_trial()
            elif now - self.phase_since > 10.0:
                self.get_logger().error('/sim/reset did not answer in 10 s; starting the next '
                                        'trial without a reset.')
                self._start_trial()

    def _start_trial(self) -> None:
        if self.n_trials and self.trial >= self.n_trials:
            self._report()
            self.done = True
            self._enter('finished')
            return
        self.trial += 1
        try:
            self.target = self.planner.next_target(self.trial, self.scene)
        except ValueError as exc:
            self.get_logger().error(str(exc))
            self.done = True
            return
        self.result = None
        self.trial_start = time.monotonic()
        msg = TaskTarget(trial=self.trial, object_id=self.target.object_id,
                         colour=self.target.colour, shape=self.target.shape,
                         scene=self.scene_name)
        msg.header.stamp = self.get_clock().now().to_msg()
        self.target_pub.publish(msg)
        self.get_logger().info(f'Trial {self.trial}: grasp the {self.target.label}.')
        self._enter('trial')

    def _finish(self, grasped: str, success: bool, timed_out: bool) -> None:
        assert self.target is not None
        outcome = TrialOutcome(self.trial, self.target.label, grasped, success,
                               time.monotonic() - self.trial_start, timed_out)
        self.planner.record(outcome)
        verdict = ('timed out' if timed_out else
                   'correct object grasped' if outcome.correct else
                   f'grasped the {grasped}' if success else 'grasp failed')
        self.get_logger().info(f'Trial {self.trial} ({self.target.label}): {verdict} after '
                               f'{outcome.duration:.1f} s.')
        self._enter('settling')

    def _reset(self) -> None:
        if not self.reset_client.service_is_ready():
            self.get_logger().warning('/sim/reset is not available; next trial without a reset.')
            self._start_trial()
            return
        self.reset_future = self.reset_client.call_async(ResetSim.Request(seed=-1))
        self._enter('resetting')

    def _report(self) -> None:
        s = self.planner.summary()
        self.get_logger().info(
            f"{s['trials']} trials: grasp success {100 * s['success_rate']:.1f} %, correct "
            f"object {100 * s['correct_rate']:.1f} %, {s['timeouts']} timeouts, trial time "
            f"mean {s['mean_time_s']:.1f} s, median {s['median_time_s']:.1f} s.")


def main(args: list[str] | None = None) -> int:
    """Run trials until ``n_trials`` are done or Ctrl-C; print the tally."""
    rclpy.init(args=args)
    node = TrialManagerNode()
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    try:
        while rclpy.ok() and not node.done:
            executor.spin_once(timeout_sec=0.1)
    except KeyboardInterrupt:
        pass
    finally:
        if node.planner.outcomes and not node.done:
            node._report()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
