"""Runs grasp trials: prepares the scene, names the desired object, keeps one record per trial.

    python -m mindgrasp_experiments.trial_manager_node --ros-args -p n_trials:=5 -p seed:=1

Per trial: reset the scene (``/sim/reset``; random locations: ``/sim/load_scene`` with the
trial's one-object scene), wait until every topic of ``wait_for`` is publishing (the EEG, the
classifier, the vision: it says what it waits for, and gives up after ``ready_timeout`` s),
publish ``/task/target`` (mindgrasp_msgs/TaskTarget, transient local), then follow the trial
until the grasp result (``/task/result``), a grasp attempt that ends without one (a return to
start the person cancelled is not one: the trial goes on), no controller state change for
``stall_timeout`` s, or ``trial_timeout`` s. Every time is on the node clock
(simulated time with ``use_sim_time``), so lock-step experiments and live runs behave alike.

Records (:class:`~mindgrasp_experiments.records.TrialRecord`) are kept in ``records``; with
``records_dir`` (default ``$MINDGRASP_RUN_DIR/trials`` in a launch) they are also written as
records.csv and records.parquet after every trial. The node ends after ``n_trials`` (0: never)
and logs the tally.
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import yaml
from mindgrasp_ros.interfaces.geometry_msgs.msg import PoseStamped
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import (
    FsmState,
    GraspResult,
    MIPrediction,
    TaskTarget,
)
from mindgrasp_ros.interfaces.mindgrasp_msgs.srv import LoadScene, ResetSim
from mindgrasp_ros.interfaces.std_msgs.msg import String
from mindgrasp_ros.interfaces.visualization_msgs.msg import MarkerArray

from mindgrasp_common.markers import objects_from_markers
from mindgrasp_common.safe_files import DeferredWriter, write_atomic
from mindgrasp_experiments.protocols import (
    PROTOCOLS,
    random_locations_trial,
    set_locations_target,
)
from mindgrasp_experiments.records import TrialRecord, TrialTracker, write_records
from mindgrasp_experiments.summary import summarise
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import fail, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params, param
from mindgrasp_ros.topics import (
    BCI_PREDICTION,
    EE_POSE,
    EEG_RAW,
    FSM_STATE,
    LATCHED_QUEUE,
    SIM_OBJECTS,
    TASK_RESULT,
    TASK_TARGET,
    VIRTUAL_SUBJECT_INTENT,
    VISION_DETECTIONS,
)

#: topics the trial manager can wait for before a trial (any message counts)
WAITABLE = (EEG_RAW.name, BCI_PREDICTION.name, VISION_DETECTIONS.name)


@dataclass
class TrialManagerParams:
    """Parameters of the trial manager (seconds of the node clock)."""

    protocol: str = param('set_locations', 'the grasp protocol', choices=PROTOCOLS)
    n_trials: int = param(0, 'trials before the node ends (0: never)', min=0)
    first_trial: int = param(1, 'number of the first trial (draws depend on seed and trial)',
                             min=1)
    seed: int = param(0, 'seed of the protocol draws', min=0)
    targets: str = param('', "set locations: labels to ask for in turn ('red cube, blue "
                             "sphere'); '' draws them from the seed")
    subject: str = param('', 'who drives the controller, written into the records')
    trial_timeout: float = param(600.0, 'a trial without a grasp ends then (0 never)', unit='s',
                                 min=0.0)
    stall_timeout: float = param(120.0, 'a trial without a controller state change ends then '
                                        '(0 never)', unit='s', min=0.0)
    settle_time: float = param(3.0, 'after a grasp, before the scene is reset', unit='s',
                               min=0.0)
    wait_for: list[str] = param(list(WAITABLE), 'topics that must publish before a trial')
    ready_timeout: float = param(60.0, 'give up when they do not publish by then', unit='s',
                                 min=0.0)
    service_timeout: float = param(10.0, 'wait this long for the simulator services', unit='s',
                                   min=0.0)
    records_dir: str = param('', "folder for records.csv/.parquet ('' = $MINDGRASP_RUN_DIR/"
                                 "trials in a launch, else none)")

    def __post_init__(self) -> None:
        unknown = [t for t in self.wait_for if t and t not in WAITABLE]
        if unknown:
            msg = (f'wait_for lists {unknown}; the trial manager can wait for {list(WAITABLE)}.')
            raise ValueError(msg)


class TrialManagerNode(rclpy.node.Node):
    """Trial loop of the grasp protocols (see the module docstring)."""

    node_traits = NodeTraits(name='trial_manager', trial_manager=True, prompts=('test',),
                             task_parameter='protocol')

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.done = rclpy.task.Future()
        self.params = p = declare_params(self, TrialManagerParams)
        self.targets = [t.strip() for t in str(p.targets).split(',') if t.strip()]
        self.tracker = TrialTracker(p.protocol, p.subject, int(p.seed))
        self.records: list[TrialRecord] = []
        records_dir = p.records_dir or (
            str(Path(os.environ['MINDGRASP_RUN_DIR']) / 'trials')
            if os.environ.get('MINDGRASP_RUN_DIR') else '')
        self.records_dir = Path(records_dir) if records_dir else None
        # a full disk costs only what cannot be written: records stay in memory, go to a
        # fallback folder the log names, and land in records_dir when space returns
        self.record_files = DeferredWriter(self.records_dir.parent if self.records_dir else None)
        self.target_pub = self.create_publisher(TaskTarget, TASK_TARGET.name, TASK_TARGET.qos)
        self.create_subscription(MarkerArray, SIM_OBJECTS.name, self.objects_callback,
                                 SIM_OBJECTS.qos)
        self.create_subscription(GraspResult, TASK_RESULT.name, self.result_callback,
                                 TASK_RESULT.qos)
        self.create_subscription(FsmState, FSM_STATE.name, self.fsm_callback, FSM_STATE.qos)
        self.create_subscription(MIPrediction, BCI_PREDICTION.name, self.prediction_callback,
                                 BCI_PREDICTION.qos)
        self.create_subscription(String, VIRTUAL_SUBJECT_INTENT.name, self.intent_callback,
                                 LATCHED_QUEUE.profile())
        self.create_subscription(PoseStamped, EE_POSE.name, self.ee_callback, EE_POSE.qos)
        # readiness: any message type will do; the last arrival time of each topic is kept
        self.last_seen: dict[str, float] = {}
        for topic in p.wait_for:
            if topic and topic != BCI_PREDICTION.name:
                self._watch(topic)
        self.reset_client = self.create_client(ResetSim, '/sim/reset')
        self.load_client = self.create_client(LoadScene, '/sim/load_scene')
        self.scene: dict[int, tuple[str, float, float]] = {}   # id -> (label, x, y)
        self.fsm_state = 0
        self.trial = int(p.first_trial) - 1
        self.n_done = 0
        self.target_id = -1
        self.target_label = ''
        self.result: GraspResult | None = None
        self.phase = 'preparing'
        self.phase_since = self.now_s()
        self.future = None
        self.said_waiting = ''
        self.error: str | None = None
        self._scene_dir: Path | None = None
        self._enter('starting')
        self.create_timer(0.1, self.tick)

    # ------------------------------------------------------------------ inputs
    def now_s(self) -> float:
        """Node clock (s): wall time, or simulated time with use_sim_time."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _watch(self, topic: str) -> None:
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, EEGChunk

        # /eeg/raw: sensor-data QoS (depth 5), not the table's depth 100: only arrivals count
        kinds = {EEG_RAW.name: (EEGChunk, rclpy.qos.qos_profile_sensor_data),
                 VISION_DETECTIONS.name: (DetectionArray, VISION_DETECTIONS.qos)}
        kind, qos = kinds[topic]
        self.create_subscription(kind, topic, lambda _m, t=topic: self._seen(t), qos)

    def _seen(self, topic: str) -> None:
        self.last_seen[topic] = self.now_s()

    def objects_callback(self, msg: MarkerArray) -> None:
        self.scene = {o.object_id: (o.label, float(o.position[0]), float(o.position[1]))
                      for o in objects_from_markers(msg.markers)}

    def result_callback(self, msg: GraspResult) -> None:
        """A lift ends the trial; a drop is noted and the trial goes on (the controller grasps
        again after a slip, ``grasp_retries``), until a lift, the controller gives up, or a
        timeout."""
        if self.phase != 'trial' or self.result is not None:
            return
        self.tracker.on_result(msg.grasped_object, bool(msg.success), self.now_s(),
                               float(msg.lift_height))
        if msg.success:
            self.result = msg
        else:
            self.get_logger().info(f'Trial {self.trial}: the {msg.grasped_object} was dropped '
                                   f'(lift to {msg.lift_height:.3f} m); the trial goes on.')

    def fsm_callback(self, msg: FsmState) -> None:
        self.fsm_state = int(msg.state)
        if self.phase == 'trial':
            self.tracker.on_state(int(msg.state), msg.object_of_interest, self.now_s(),
                                  msg.reason)
            if msg.paradigm == 'scan' and self.tracker.record is not None:
                self.tracker.record.answer_pair = msg.answer_pair

    def prediction_callback(self, msg: MIPrediction) -> None:
        self._seen(BCI_PREDICTION.name)
        if self.phase == 'trial':
            self.tracker.on_prediction(int(msg.class_index), float(msg.certainty), self.now_s(),
                                       list(msg.class_names))

    def intent_callback(self, msg: String) -> None:
        self.tracker.on_intent(msg.data)

    def ee_callback(self, msg: PoseStamped) -> None:
        if self.phase == 'trial':
            p = msg.pose.position
            self.tracker.on_ee_pose(float(p.x), float(p.y), float(p.z))

    # ------------------------------------------------------------------ trial loop
    def _enter(self, phase: str) -> None:
        self.phase, self.phase_since = phase, self.now_s()

    def tick(self) -> None:
        """Every 0.1 s of node time: move the trial loop on."""
        if self.done.done():
            return
        now = self.now_s()
        if self.phase == 'starting':
            # trial 1 waits for the simulator's services (nodes may start in any order)
            client = self.load_client if self.params.protocol == 'random_locations' \
                else self.reset_client
            if client.service_is_ready() or now - self.phase_since > self.params.service_timeout:
                self._begin_trial()
        elif self.phase == 'preparing':
            if self.future is None or self.future.done():
                ok = self.future is None or self.future.result() is None or \
                    self.future.result().success
                if not ok:
                    self.fail(f'The simulator could not prepare trial {self.trial}: '
                              f'{self.future.result().message}')
                    return
                self.future = None
                self._enter('waiting')
            elif now - self.phase_since > self.params.service_timeout:
                self.fail(f'The simulator did not answer the scene reset of trial {self.trial} '
                          f"within {self.params.service_timeout:g} s; is the sim node running?")
        elif self.phase == 'waiting':
            self._wait_until_ready(now)
        elif self.phase == 'trial':
            self._follow_trial(now)
        elif self.phase == 'settling' and (
                (self.fsm_state in (FsmState.OBJECT_SEARCH, 0)
                 and now - self.phase_since > self.params.settle_time)
                or now - self.phase_since > 30.0):
            # the controller brought the arm home before the scene is reset under it
            self._begin_trial()

    def _begin_trial(self) -> None:
        """Reset the scene for the next trial (or end after ``n_trials``)."""
        if self.params.n_trials and self.n_done >= self.params.n_trials:
            self._report()
            self._enter('finished')
            self.done.set_result(0)
            return
        self.trial += 1
        self.result = None
        self.scene = {}
        if self.params.protocol == 'random_locations':
            spec = random_locations_trial(int(self.params.seed), self.trial)
            path = self._scene_file(spec.scene())
            self.future = self._call(self.load_client, LoadScene.Request(scene=str(path),
                                                                         seed=-1))
        else:
            self.future = self._call(self.reset_client, ResetSim.Request(seed=-1))
        self._enter('preparing')

    def _call(self, client, request):
        if not client.service_is_ready():
            self.get_logger().warning(f'{client.srv_name} is not available; trial '
                                      f'{self.trial} starts without a scene reset.')
            return None
        return client.call_async(request)

    def _scene_file(self, scene: dict) -> Path:
        """The scene as a file for /sim/load_scene, in the run directory (a hand-over to the
        simulator: in the system's temporary folder when the run directory is full)."""
        name = f"{scene['name']}.yaml"
        text = yaml.safe_dump(scene, sort_keys=False)
        try:
            if self._scene_dir is None:
                base = self.records_dir.parent if self.records_dir is not None else None
                self._scene_dir = Path(tempfile.mkdtemp(prefix='scenes_', dir=base))
            return write_atomic(self._scene_dir / name,
                                lambda tmp: tmp.write_text(text, encoding='utf-8'))
        except OSError:
            self._scene_dir = Path(tempfile.mkdtemp(prefix='mindgrasp_scenes_'))
            path = self._scene_dir / name
            path.write_text(text, encoding='utf-8')
            return path

    def _wait_until_ready(self, now: float) -> None:
        missing = [t for t in self.params.wait_for
                   if t and now - self.last_seen.get(t, -math.inf) > 1.0]
        if self.scene == {}:
            missing.insert(0, SIM_OBJECTS.name)
        if missing:
            waited = now - self.phase_since
            text = ', '.join(missing)
            if text != self.said_waiting:
                self.said_waiting = text
                self.get_logger().info(f'Trial {self.trial} waits for {text} to publish '
                                       f"(up to {self.params.ready_timeout:g} s).")
            if waited > self.params.ready_timeout:
                self.fail(f'Gave up before trial {self.trial}: no messages on {text} after '
                          f"{self.params.ready_timeout:g} s. Check that the nodes publishing "
                          f'them run (mindgrasp topic hz {missing[0]}).')
            return
        self.said_waiting = ''
        self._start_trial(now)

    def _choose_target(self) -> tuple[int, str]:
        ids = sorted(self.scene)
        if self.params.protocol == 'random_locations':
            return ids[0], self.scene[ids[0]][0]
        if self.targets:
            label = self.targets[(self.trial - 1) % len(self.targets)]
            for i in ids:
                if self.scene[i][0] == label:
                    return i, label
            known = ', '.join(sorted(v[0] for v in self.scene.values()))
            msg = f'Target {label!r} is not in the scene; the scene has: {known}.'
            raise ValueError(msg)
        i = ids[set_locations_target(int(self.params.seed), self.trial, len(ids))]
        return i, self.scene[i][0]

    def _start_trial(self, now: float) -> None:
        try:
            self.target_id, self.target_label = self._choose_target()
        except ValueError as exc:
            self.fail(str(exc))
            return
        _label, x, y = self.scene[self.target_id]
        self.tracker.start(self.trial, self.target_label, self.target_id, now, (x, y),
                           state=self.fsm_state, n_objects=len(self.scene))
        colour, _, shape = self.target_label.partition(' ')
        msg = TaskTarget(trial=self.trial, object_id=self.target_id, colour=colour, shape=shape,
                         scene=str(self.params.protocol))
        msg.header.stamp = self.get_clock().now().to_msg()
        self.target_pub.publish(msg)
        self.get_logger().info(f'Trial {self.trial}: grasp the {self.target_label}.')
        self._enter('trial')

    def _follow_trial(self, now: float) -> None:
        tracker = self.tracker
        if self.result is not None:
            self._finish(now, '', '')
        elif self.params.trial_timeout > 0 and now - tracker.start_time > self.params.trial_timeout:
            self._finish(now, 'timeout', f"no grasp within {self.params.trial_timeout:g} s")
        elif self.params.stall_timeout > 0 and \
                now - tracker.last_state_change > self.params.stall_timeout:
            self._finish(now, 'stalled', f'no controller state change for '
                                         f"{self.params.stall_timeout:g} s (state "
                                         f'{self.fsm_state})')
        elif tracker.attempt_over:      # a return the person cancelled goes on
            self._finish(now, 'no_grasp', 'the grasp attempt ended without a lift')

    def _finish(self, now: float, failure: str, reason: str) -> None:
        rec = self.tracker.finish(now, failure, reason)
        self.records.append(rec)
        self.n_done += 1
        verdict = ('correct object grasped' if rec.correct_and_successful else
                   f'grasped the {rec.grasped}' if rec.success else
                   f'failed ({rec.failure}: {rec.reason})')
        self.get_logger().info(f'Trial {rec.trial} ({rec.desired}): {verdict} after '
                               f"{rec.duration_s:.1f} s: {rec.outcome.replace('_', ' ')}.")
        self._save_records()
        last = self.params.n_trials and self.n_done >= self.params.n_trials
        if last:
            self._begin_trial()          # ends the node
        else:
            self._enter('settling')

    def destroy_node(self) -> None:
        """Stopped before the trials were done (Ctrl-C): the running trial is recorded as
        interrupted and the tally logged."""
        if self.tracker.active:
            self.finish_interrupted('stopped before the trial ended')
            self._report()
        for line in self.record_files.close():
            self.get_logger().error(line)
        super().destroy_node()

    def finish_interrupted(self, reason: str, failure: str = 'interrupted') -> None:
        """End the running trial now: recorded with ``failure`` (``interrupted``, Ctrl-C: left
        out of the rates; or the engine's ``timeout`` / ``node_error``)."""
        if self.tracker.active:
            rec = self.tracker.finish(self.now_s(), failure, reason)
            self.records.append(rec)
            self._save_records()

    def _save_records(self) -> None:
        """Write records.csv/.parquet; a disk fault is one warning, never a crash."""
        if self.records_dir is None:
            return
        records = list(self.records)
        for line in self.record_files.write(self.records_dir, 'trial records',
                                            lambda folder: write_records(records, folder)):
            self.get_logger().warning(line)

    def fail(self, reason: str) -> None:
        """Stop the trials with an error (the node ends, exit code 1)."""
        self.error = reason
        self._enter('failed')
        fail(self, reason)

    def _report(self) -> None:
        if not self.records:
            return
        s = summarise(self.records)
        cut = (f" ({s['interrupted_trials']} interrupted, not counted)"
               if s['interrupted_trials'] else '')
        if not s['trials']:
            self.get_logger().info(f'No finished trial{cut}.')
            return
        self.get_logger().info(
            f"{s['trials']} trials{cut}: correct grasp "
            f"{100 * s['correct_and_successful_rate']:.1f} %, wrong grasp "
            f"{100 * s['wrong_grasp_rate']:.1f} %, no grasp {100 * s['no_grasp_rate']:.1f} %; "
            f"grasp success {100 * s['success_rate']:.1f} %, correct choice "
            f"{100 * s['correct_choice_rate']:.1f} %, mean trial time "
            f"{s['mean_duration_s']:.1f} s.")


def main(args: list[str] | None = None) -> int:
    """Run trials until ``n_trials`` are done or Ctrl-C; log the tally. Exit 1 on an error."""
    return run_node(TrialManagerNode, args)


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
