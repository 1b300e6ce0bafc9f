"""In-process, lock-step closed loop: Simulation -> VisionPipeline -> GraspFsm -> Simulation.

The same classes the nodes run, called in a fixed order on simulated time: physics at the
simulator's rate, the controller at ``control_hz``, camera frames (render + vision) at the camera
rate. No threads, no DDS, no wall clock, so a trial is deterministic for a seed and runs as fast as
the CPU allows. Used by ``mindgrasp experiment random-locations``, ``benchmarks/grasp.py`` and the
closed-loop tests.

Only the experiment bookkeeping (success, the oracle subject) reads the simulator's ground truth;
the controller sees camera images, depth, joint states and finger contacts.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from mindgrasp_common.geometry import wrap_angle
from mindgrasp_fsm.conversions import gripper_from_fingers, vision_frame_from_result
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.types import CameraModel, FsmInputs, JointStateIn, MiClass, Prediction, State

#: an object counts as grasped when it is held above this height (m; original MIndGrasp code)
SUCCESS_HEIGHT = 0.22


@dataclass
class TrialOutcome:
    """Result of one closed-loop trial (times in simulated seconds)."""

    success: bool
    duration: float                 # s from the start to the end of the trial
    time_to_grasp: float            # s until the grasp was checked (NaN when it never was)
    lift_height: float              # m, highest lift of the target above its start height
    attempts: int                   # grasp attempts (1 + retries)
    reason: str
    grasped_object: str = ''
    detected_shape: str = 'unknown'
    states: list[int] = field(default_factory=list)
    vision_times: list[float] = field(default_factory=list)   # wall s per processed frame
    wall_time: float = 0.0


class OracleBci:
    """A virtual subject who always imagines the right class for a target object.

    It knows where the target is (the person looking at the scene does) and turns the robot
    towards it (left/right hand), selects and approaches it (both hands) when it is in front of
    the camera, and otherwise keeps imagining both hands. Predictions come every ``period`` s with
    certainty ``certainty``.
    """

    def __init__(self, target_id: int, certainty: float = 1.0, period: float = 0.1,
                 aim_tolerance: float = 0.12) -> None:
        self.target_id = int(target_id)
        self.certainty = float(certainty)
        self.period = float(period)
        self.aim_tolerance = float(aim_tolerance)
        self._last: Prediction | None = None

    def __call__(self, sim: object, t: float) -> Prediction:
        """The latest prediction at simulated time ``t`` (s)."""
        if self._last is not None and t - self._last.stamp < self.period:
            return self._last
        target = sim.objects()[self.target_id]
        cam_pos, cam_quat = sim.camera_pose()
        import pybullet as pb

        axis = np.array(pb.getMatrixFromQuaternion(cam_quat)).reshape(3, 3)[:, 2]
        heading = math.atan2(axis[1], axis[0]) if math.hypot(axis[0], axis[1]) > 0.2 else \
            math.atan2(cam_pos[1], cam_pos[0])
        bearing = math.atan2(target.position[1] - cam_pos[1], target.position[0] - cam_pos[0])
        err = wrap_angle(bearing - heading)
        if err > self.aim_tolerance:
            cls = MiClass.LEFT_HAND
        elif err < -self.aim_tolerance:
            cls = MiClass.RIGHT_HAND
        else:
            cls = MiClass.BOTH_HANDS
        self._last = Prediction(int(cls), self.certainty, t)
        return self._last


class LockstepLoop:
    """Step a :class:`~mindgrasp_sim.simulation.Simulation`, a vision pipeline and a
    :class:`GraspFsm` together.

    Parameters
    ----------
    sim : Simulation
    pipeline : VisionPipeline
    fsm : GraspFsm
    control_hz : float
        Controller rate (Hz); rounded to a whole number of physics steps.
    camera_hz : float or None
        Camera + vision rate (Hz); default the simulator camera's ``rate_hz``.
    """

    def __init__(self, sim: object, pipeline: object, fsm: GraspFsm, control_hz: float = 60.0,
                 camera_hz: float | None = None) -> None:
        self.sim = sim
        self.pipeline = pipeline
        self.fsm = fsm
        self.steps_per_tick = max(1, round(sim.physics_hz / control_hz))
        tick = self.steps_per_tick / sim.physics_hz
        cam_hz = float(camera_hz or sim.camera.rate_hz)
        self.ticks_per_frame = max(1, round(1.0 / (cam_hz * tick)))
        k, width, height = sim.camera_intrinsics()
        self.camera = CameraModel.from_k(width, height, k)
        self.fsm.params.control_period = tick

    def run(self, target_id: int, timeout: float = 120.0, oracle: OracleBci | None = None,
            success_height: float = SUCCESS_HEIGHT) -> TrialOutcome:
        """Run one trial from the current simulator state until the controller has returned to
        start after a grasp attempt, or ``timeout`` simulated seconds."""
        sim, fsm = self.sim, self.fsm
        wall0 = time.perf_counter()
        t0 = sim.time
        fsm.reset(t0)
        self.pipeline.reset()
        start_z = float(sim.objects()[target_id].position[2])
        lift = 0.0
        frame = None
        prediction = None
        states = [int(fsm.state)]
        time_to_grasp = math.nan
        vision_times: list[float] = []
        detected_shape = 'unknown'
        reason = f'timed out after {timeout:.0f} s'
        tick = 0
        finished = False
        while sim.time - t0 < timeout:
            t = sim.time
            if oracle is not None:
                prediction = oracle(sim, t)
            if tick % self.ticks_per_frame == 0:
                rgb, depth = sim.render_camera()
                w0 = time.perf_counter()
                mi = prediction.class_index if prediction is not None else None
                result = self.pipeline.process(rgb, depth, mi_class=mi,
                                               classify=fsm.state == State.FINAL_APPROACH)
                vision_times.append(time.perf_counter() - w0)
                frame = vision_frame_from_result(result, t)
                obj = sim.objects()[target_id]
                lift = max(lift, float(obj.position[2]) - start_z)
            gs = sim.gripper_state()
            q, qd = sim.joint_readings()     # what the encoders report (realism: noisy)
            out = fsm.tick(FsmInputs(
                time=t,
                joints=JointStateIn(q, qd, t),
                prediction=prediction, vision=frame,
                gripper=gripper_from_fingers(gs['positions'], t, gs['contacts'],
                                             gs['efforts']),
                camera=self.camera))
            if int(out.state) != states[-1]:
                states.append(int(out.state))
            if out.state == State.FINAL_APPROACH and frame is not None and \
                    frame.object_of_interest is not None and \
                    frame.object_of_interest.shape != 'unknown':
                detected_shape = frame.object_of_interest.shape
            for event in out.events:
                if event.startswith('lock 5->6') and fsm.outcome == 'holding':
                    time_to_grasp = t - t0
                if event.startswith('enter 1 from 6'):
                    finished = True
                    reason = event.split(': ', 1)[-1]
            sim.set_joint_velocities(out.joint_velocities)
            sim.set_gripper(out.gripper.position)
            if finished:
                break
            sim.step(self.steps_per_tick)
            tick += 1
        held = sim.held_object()
        obj = sim.objects()[target_id]
        success = held is not None and held.id == target_id and \
            float(obj.position[2]) > success_height
        if not success and finished:
            reason = f'not held at the end ({fsm.outcome or "no grasp"}): {fsm.reason}'
        return TrialOutcome(
            success=success, duration=sim.time - t0, time_to_grasp=time_to_grasp,
            lift_height=lift, attempts=states.count(int(State.GRASP_OBJECT)),
            reason=reason, grasped_object=held.label if held is not None else '',
            detected_shape=detected_shape, states=states, vision_times=vision_times,
            wall_time=time.perf_counter() - wall0)
