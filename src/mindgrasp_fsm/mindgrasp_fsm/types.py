"""Plain data types exchanged with :class:`mindgrasp_fsm.grasp_fsm.GraspFsm` (no ROS)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

CLASS_NAMES = ('left_hand', 'right_hand', 'both_hands', 'both_feet')


class State(IntEnum):
    """The paper's six FSM states (same numbers as mindgrasp_msgs/FsmState)."""

    OBJECT_SEARCH = 1
    CENTER_OBJECT = 2
    INITIAL_APPROACH = 3
    FINAL_APPROACH = 4
    GRASP_OBJECT = 5
    RETURN_TO_START = 6


STATE_NAMES = {
    State.OBJECT_SEARCH: 'Object Search',
    State.CENTER_OBJECT: 'Center Object',
    State.INITIAL_APPROACH: 'Initial Approach',
    State.FINAL_APPROACH: 'Final Approach',
    State.GRASP_OBJECT: 'Grasp Object',
    State.RETURN_TO_START: 'Return to Start',
}


class MiClass(IntEnum):
    """Motor-imagery classes (mindgrasp_msgs/MIPrediction)."""

    LEFT_HAND = 0
    RIGHT_HAND = 1
    BOTH_HANDS = 2
    BOTH_FEET = 3


@dataclass(frozen=True)
class Prediction:
    """Latest MI decision. ``stamp``: time of the last decoded sample (s, controller clock)."""

    class_index: int
    certainty: float
    stamp: float


@dataclass(frozen=True)
class ObjectObservation:
    """The object of interest in one camera frame (pixels of that frame, metres)."""

    colour: str
    shape: str                      # cube | cylinder | sphere | unknown
    bbox: tuple[float, float, float, float]  # x_offset, y_offset, width, height (px)
    centre_x: float                 # px
    centre_y: float                 # px
    pixel_fraction: float           # object pixels / image area
    distance: float                 # camera-to-object depth (m), NaN when unknown
    shape_confidence: float = 0.0

    @property
    def label(self) -> str:
        """``"<colour> <shape>"``."""
        return f'{self.colour} {self.shape}'.strip()


@dataclass(frozen=True)
class VisionFrame:
    """The vision result of one camera frame. ``stamp``: image time (s)."""

    stamp: float
    image_width: int
    image_height: int
    object_of_interest: ObjectObservation | None = None
    n_detections: int = 0


@dataclass(frozen=True)
class CameraModel:
    """Pinhole intrinsics of the eye-in-hand camera (sensor_msgs/CameraInfo K), pixels."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_k(cls, width: int, height: int, k: np.ndarray) -> CameraModel:
        """From a row-major 3x3 (or 9-vector) K matrix."""
        k = np.asarray(k, dtype=float).reshape(3, 3)
        return cls(int(width), int(height), float(k[0, 0]), float(k[1, 1]), float(k[0, 2]),
                   float(k[1, 2]))

    def scaled_to(self, width: int, height: int) -> CameraModel:
        """Intrinsics for an image of another size (same field of view)."""
        sx, sy = width / self.width, height / self.height
        return CameraModel(width, height, self.fx * sx, self.fy * sy, self.cx * sx, self.cy * sy)

    def backproject(self, u: float, v: float, depth: float) -> np.ndarray:
        """Point (m, optical frame: x right, y down, z forward) at pixel (u, v) and depth z."""
        return np.array([(u - self.cx) / self.fx * depth, (v - self.cy) / self.fy * depth, depth])


@dataclass(frozen=True)
class GripperState:
    """Measured gripper: ``opening`` 1 fully open .. 0 fully closed; finger force (N)."""

    opening: float
    force: float
    stamp: float
    contact: bool | None = None     # from contact sensing when available
    fingers_in_contact: int | None = None   # how many fingers touch the object, when sensed
    efforts: tuple[float, ...] | None = None  # per-finger motor efforts (N m), when sensed


@dataclass(frozen=True)
class JointStateIn:
    """Arm joint state, 6 joints in the controller's order. Positions rad, velocities rad/s."""

    position: np.ndarray
    velocity: np.ndarray
    stamp: float


@dataclass
class FsmInputs:
    """Everything the controller sees at one tick. ``time``: controller clock now (s)."""

    time: float
    joints: JointStateIn | None = None
    prediction: Prediction | None = None
    vision: VisionFrame | None = None
    gripper: GripperState | None = None
    camera: CameraModel | None = None


@dataclass(frozen=True)
class GripperCommand:
    """``position`` 0 open .. 1 closed; ``max_force`` (N) the fingers may apply."""

    position: float
    max_force: float


@dataclass
class FsmOutput:
    """Commands and state of one tick."""

    joint_velocities: np.ndarray    # shape (6,), rad/s
    gripper: GripperCommand
    state: State
    previous_state: State
    locked: bool
    stopped: bool
    reason: str
    object_of_interest: str = ''
    phase: str = ''                 # sub-step inside the grasp policy
    grasp_attempts: int = 0
    grasp_outcome: str = ''         # '', 'holding', 'failed'
    events: list[str] = field(default_factory=list)

    @property
    def state_name(self) -> str:
        """Human-readable state name (the paper's)."""
        return STATE_NAMES[self.state]
