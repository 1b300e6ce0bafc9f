"""Build the controller's inputs from vision results, simulator readings and ROS messages.

Duck-typed on purpose: the functions read attributes only, so they serve the in-process lock-step
loop (:class:`mindgrasp_vision.pipeline.FrameResult`) and the node (``DetectionArray``) alike.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from mindgrasp_common.robot import FINGER_CLOSED, FINGER_OPEN
from mindgrasp_fsm.types import GripperState, ObjectObservation, VisionFrame


def observation_from_detection(det: object) -> ObjectObservation:
    """From a vision ``Detection`` (dataclass) or a ``mindgrasp_msgs/Detection`` message."""
    bbox = det.bbox
    if hasattr(bbox, 'x_offset'):     # sensor_msgs/RegionOfInterest
        box = (float(bbox.x_offset), float(bbox.y_offset), float(bbox.width), float(bbox.height))
    else:
        box = tuple(float(v) for v in bbox)
    return ObjectObservation(
        colour=str(det.colour), shape=str(det.shape or 'unknown'), bbox=box,  # type: ignore[arg-type]
        centre_x=float(det.centre_x), centre_y=float(det.centre_y),
        pixel_fraction=float(det.pixel_fraction),
        distance=float(det.distance) if det.distance is not None else math.nan,
        shape_confidence=float(getattr(det, 'shape_confidence', 0.0)))


def vision_frame_from_result(result: object, stamp: float) -> VisionFrame:
    """From a :class:`mindgrasp_vision.pipeline.FrameResult`; ``stamp``: image time (s)."""
    target = result.target
    return VisionFrame(stamp=float(stamp), image_width=int(result.width),
                       image_height=int(result.height),
                       object_of_interest=None if target is None
                       else observation_from_detection(target),
                       n_detections=len(result.detections))


def vision_frame_from_msg(msg: object, stamp: float) -> VisionFrame:
    """From a ``mindgrasp_msgs/DetectionArray``; ``stamp``: image time (s)."""
    idx = int(msg.object_of_interest)
    dets = list(msg.detections)
    ooi = observation_from_detection(dets[idx]) if 0 <= idx < len(dets) else None
    return VisionFrame(stamp=float(stamp), image_width=int(msg.image_width),
                       image_height=int(msg.image_height), object_of_interest=ooi,
                       n_detections=len(dets))


def gripper_from_fingers(positions: Sequence[float], stamp: float,
                         contacts: Sequence[bool] | None = None,
                         efforts: Sequence[float] | None = None,
                         open_angle: float | Sequence[float] = FINGER_OPEN,
                         closed_angle: float | Sequence[float] = FINGER_CLOSED
                         ) -> GripperState:
    """Gripper state from finger joint angles (rad), optional per-finger contact flags and
    efforts (N m). Opening: 1 open .. 0 closed (mean over fingers); contact: at least two fingers
    touch (thumb against a finger), when contact flags are given; force: sum of the absolute
    efforts (N m), NaN without them. ``open_angle`` and ``closed_angle``: one range for every
    joint, or one per joint (a closure synergy whose joints move over different ranges, as the
    Jaco hand's proximal and distal joints: the mean of the joints' own closures)."""
    # plain floats: three fingers, twice per control tick, where numpy's per-call cost dominates
    pos = [float(v) for v in positions]
    if isinstance(open_angle, (int, float)) and isinstance(closed_angle, (int, float)):
        mean = math.fsum(pos) / len(pos) if pos else math.nan
        opening = min(max((closed_angle - mean) / (closed_angle - open_angle), 0.0), 1.0)
    else:
        shut = [(c - p) / (c - o) for p, o, c in zip(pos, open_angle, closed_angle, strict=True)]
        opening = min(max(math.fsum(shut) / len(shut), 0.0), 1.0) if shut else math.nan
    n = None if contacts is None else sum(1 for c in contacts if c)
    contact = None if n is None else n >= 2
    per_finger = None
    force = math.nan
    if efforts is not None:
        eff = [float(e) for e in efforts]
        force = math.fsum(abs(e) for e in eff)
        if len(eff) == len(pos):
            per_finger = tuple(eff)
    return GripperState(opening=opening, force=force, stamp=float(stamp), contact=contact,
                        fingers_in_contact=n, efforts=per_finger)
