"""Plain data types exchanged with :class:`mindgrasp_fsm.grasp_fsm.GraspFsm` (no ROS); the
shared ones (predictions, camera model, states, MI classes) come from :mod:`mindgrasp_common`."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from mindgrasp_common.mi import CLASS_NAMES, MiClass
from mindgrasp_common.states import STATE_NAMES, State
from mindgrasp_common.types import CameraModel, Prediction

# shared with the other packages (defined in mindgrasp_common), used here by the controller
__all__ = [
    'CLASS_NAMES', 'STATE_NAMES', 'CameraModel', 'FsmInputs', 'FsmOutput', 'GripperCommand',
    'GripperState', 'JointStateIn', 'MiClass', 'ObjectObservation', 'Prediction', 'State',
    'VisionFrame',
]


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
        """``"<colour> <shape>"``, or ``"<colour> object"`` while the shape is unknown (not yet
        classified): the log said "selected the yellow unknown"."""
        shape = 'object' if self.shape in ('', 'unknown') else self.shape
        return f'{self.colour} {shape}'.strip()


@dataclass(frozen=True)
class VisionFrame:
    """The vision result of one camera frame. ``stamp``: image time (s)."""

    stamp: float
    image_width: int
    image_height: int
    object_of_interest: ObjectObservation | None = None
    n_detections: int = 0


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
    # the latest joint-state message that was refused (NaN/inf, wrong names or sizes): its time
    # of receipt (s, controller clock) and what was wrong; ``joints`` keeps the last good one
    joint_fault: tuple[float, str] | None = None


@dataclass(frozen=True)
class GripperCommand:
    """``position`` 0 open .. 1 closed; ``max_force`` (N) the fingers may apply."""

    position: float
    max_force: float


class StopKind(enum.StrEnum):
    """Why a stopped controller holds still, which decides how loudly a user is told."""

    NONE = ''                         # not stopped
    AWAITING_INPUT = 'awaiting_input'  # a first input not received yet: how every start begins
    FAULT = 'fault'                   # an input went stale, broke, or a fresh decision is awaited


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
    grasp_outcome: str = ''         # '', 'holding', 'failed', 'cancelled'
    events: list[str] = field(default_factory=list)
    paradigm: str = ''              # 'paper', 'scan' or 'autonomous'
    offered: bool = False           # scan: the object of interest is offered for confirmation
    confirm_evidence: float = 0.0   # scan: confirmation evidence / confirm_threshold (0..1)
    cancel_evidence: float = 0.0    # scan: cancel evidence / cancel_threshold (0..1)
    stop_kind: StopKind = StopKind.NONE   # why ``stopped`` holds (NONE when moving)

    @property
    def state_name(self) -> str:
        """Human-readable state name (the paper's)."""
        return STATE_NAMES[self.state]
