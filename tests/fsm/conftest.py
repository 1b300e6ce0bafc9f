"""Synthetic inputs for GraspFsm tests: frames, predictions, a kinematic arm and a pinhole camera.

The kinematic arm integrates the commanded joint velocities (no physics); the camera projects a
point object through the real robot model (config/robots/urdf/mindgrasp_arm.urdf), so the grasp
policy's geometry is checked without PyBullet.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import (
    CameraModel,
    FsmInputs,
    FsmOutput,
    GripperState,
    JointStateIn,
    ObjectObservation,
    Prediction,
    VisionFrame,
)

W = H = 128
CAMERA = CameraModel(W, H, 110.85, 110.85, 63.5, 63.5)
HOME = np.array(FsmParams().home_position)


def observation(cx: float = 64.0, cy: float = 64.0, fraction: float = 0.01,
                distance: float = 0.8, shape: str = 'cube', colour: str = 'red'
                ) -> ObjectObservation:
    """A synthetic object of interest at pixel (cx, cy)."""
    side = math.sqrt(fraction * W * H)
    return ObjectObservation(colour, shape, (cx - side / 2, cy - side / 2, side, side), cx, cy,
                             fraction, distance)


def frame(t: float, obs: ObjectObservation | None = None) -> VisionFrame:
    """A vision frame stamped ``t`` holding ``obs`` (or nothing)."""
    return VisionFrame(t, W, H, obs, 0 if obs is None else 1)


def inputs(t: float, q: np.ndarray | None = None, cls: int | None = 2, cert: float = 1.0,
           obs: ObjectObservation | None = None, vision: bool = True,
           gripper: GripperState | None = None) -> FsmInputs:
    """Fresh inputs at time ``t`` (s): joints, a prediction and a frame all stamped ``t``."""
    q = HOME.copy() if q is None else np.asarray(q, dtype=float)
    return FsmInputs(
        time=t, joints=JointStateIn(q, np.zeros(6), t),
        prediction=None if cls is None else Prediction(cls, cert, t),
        vision=frame(t, obs) if vision else None, gripper=gripper, camera=CAMERA)


def run(fsm: GraspFsm, t0: float, duration: float, dt: float = 0.02, **kwargs: object
        ) -> tuple[list[FsmOutput], float]:
    """Tick ``fsm`` with the same synthetic inputs for ``duration`` s; returns outputs and end."""
    outs = []
    t = t0
    while t < t0 + duration - 1e-9:
        outs.append(fsm.tick(inputs(t, **kwargs)))
        t += dt
    return outs, t


@dataclass
class PointObject:
    """A ball/cube of ``size`` (m) standing on the table at (x, y)."""

    x: float
    y: float
    size: float = 0.05
    shape: str = 'cube'

    @property
    def centre(self) -> np.ndarray:
        return np.array([self.x, self.y, self.size / 2])


def project(fsm: GraspFsm, q: np.ndarray, obj: PointObject, t: float) -> VisionFrame:
    """What the eye-in-hand camera sees of ``obj`` at joints ``q`` (pinhole model)."""
    pos, rot = fsm.kinematics.camera_pose(q)
    p = rot.T @ (obj.centre - pos)
    if p[2] <= 0.02:
        return frame(t, None)
    u = CAMERA.fx * p[0] / p[2] + CAMERA.cx
    v = CAMERA.fy * p[1] / p[2] + CAMERA.cy
    if not (0 <= u < W and 0 <= v < H):
        return frame(t, None)
    side = CAMERA.fx * obj.size / p[2]
    fraction = min(side * side / (W * H), 1.0)
    obs = ObjectObservation('red', obj.shape, (u - side / 2, v - side / 2, side, side), u, v,
                            fraction, float(p[2] - obj.size / 2))
    return frame(t, obs)


@pytest.fixture
def params() -> FsmParams:
    """Default parameters with a short lock (faster tests) and no practical acceleration
    limit, so that each tick's command shows the gains alone (the limiter is tested with the
    defaults in test_grasp_fsm.py)."""
    return FsmParams(lock_duration=0.5, paradigm='paper', max_joint_acceleration=[1e6] * 6)


@pytest.fixture
def fsm(params: FsmParams) -> GraspFsm:
    """A BCI-mode controller with the project's robot model."""
    return GraspFsm.from_params(params)


def publish_left_hand(node: object, det_pub: object, pred_pub: object, predicting: bool) -> None:
    """Publish an empty /vision/detections frame (128 x 128 px) and, when ``predicting``, a sure
    left-hand /bci/prediction, both stamped now (a driver of the fsm node in its own process)."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, MIPrediction

    stamp = node.get_clock().now().to_msg()
    det = DetectionArray(image_width=128, image_height=128, object_of_interest=-1)
    det.header.stamp = stamp
    det_pub.publish(det)
    if predicting:
        pred = MIPrediction(class_index=MIPrediction.LEFT_HAND, certainty=1.0)
        pred.header.stamp = stamp
        pred_pub.publish(pred)
