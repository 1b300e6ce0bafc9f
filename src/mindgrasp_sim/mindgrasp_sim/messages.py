"""ROS messages of the simulator's state (message classes only, no rclpy): what the node publishes,
built from :class:`~mindgrasp_sim.simulation.Simulation` readings.

Kept out of the node so that the conversions (units, encodings, frames) are tested directly.
"""

from __future__ import annotations

import numpy as np
from mindgrasp_ros.interfaces.builtin_interfaces.msg import Time
from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from mindgrasp_ros.interfaces.geometry_msgs.msg import PoseStamped, TransformStamped
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import GraspResult
from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, Image, JointState
from mindgrasp_ros.interfaces.std_msgs.msg import Header
from mindgrasp_ros.interfaces.tf2_msgs.msg import TFMessage
from mindgrasp_ros.interfaces.visualization_msgs.msg import Marker, MarkerArray

from mindgrasp_common.types import SceneObject
from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_sim.task import TaskEvent
from mindgrasp_sim.tf_tree import Transform

#: visualization_msgs/Marker types of the object shapes
MARKER_TYPE = {'cube': Marker.CUBE, 'sphere': Marker.SPHERE, 'cylinder': Marker.CYLINDER,
               'mesh': Marker.MESH_RESOURCE}
OPTICAL_FRAME = 'camera_color_optical_frame'

__all__ = ['MARKER_TYPE', 'OPTICAL_FRAME', 'camera_info', 'grasp_result', 'header',
           'image_messages', 'joint_state', 'object_markers', 'pose_stamped', 'rgb_image', 'stamp',
           'status', 'tf_message']


def stamp(ns: int) -> Time:
    """builtin_interfaces/Time of ``ns`` nanoseconds."""
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def header(time_msg: Time, frame_id: str = '') -> Header:
    return Header(stamp=time_msg, frame_id=frame_id)


def joint_state(hdr: Header, names: tuple[str, ...] | list[str], position: np.ndarray,
                velocity: np.ndarray | None = None, effort: np.ndarray | None = None
                ) -> JointState:
    """JointState: positions (rad), velocities (rad/s), efforts (N m)."""
    n = len(names)
    return JointState(header=hdr, name=list(names), position=np.asarray(position, float),
                      velocity=np.zeros(n) if velocity is None else np.asarray(velocity, float),
                      effort=np.zeros(n) if effort is None else np.asarray(effort, float))


def pose_stamped(hdr: Header, position: np.ndarray, quat_xyzw: np.ndarray) -> PoseStamped:
    """PoseStamped of a position (3,) m and a quaternion (4,) xyzw."""
    msg = PoseStamped(header=hdr)
    p, o = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = (float(v) for v in position)
    o.x, o.y, o.z, o.w = (float(v) for v in quat_xyzw)
    return msg


def image_messages(hdr: Header, rgb: np.ndarray, depth: np.ndarray) -> tuple[Image, Image]:
    """``rgb8`` colour image (rgb uint8 (H, W, 3)) and ``32FC1`` little-endian depth image
    (depth float32 (H, W), metres along the optical axis)."""
    return cv2_to_imgmsg(rgb, 'rgb8', hdr), cv2_to_imgmsg(depth, '32FC1', hdr)


def rgb_image(hdr: Header, rgb: np.ndarray) -> Image:
    """``rgb8`` image of rgb uint8 (H, W, 3)."""
    return cv2_to_imgmsg(rgb, 'rgb8', hdr)


def camera_info(hdr: Header, k: np.ndarray, width: int, height: int) -> CameraInfo:
    """CameraInfo of a pinhole camera without distortion (K (3, 3) in pixels)."""
    p = np.zeros((3, 4))
    p[:, :3] = k
    return CameraInfo(header=hdr, height=height, width=width, distortion_model='plumb_bob',
                      d=np.zeros(5), k=np.asarray(k, float).reshape(-1),
                      r=np.eye(3).reshape(-1), p=p.reshape(-1))


def object_markers(hdr: Header, objects: list[SceneObject]) -> MarkerArray:
    """One marker per object: id, shape as the marker type, pose, size (m), rgba and the label
    ``"<colour> <shape>"`` as text, in namespace ``objects``."""
    markers = []
    for obj in objects:
        m = Marker(header=hdr, ns='objects', id=obj.object_id, type=MARKER_TYPE[obj.shape],
                   action=0, text=obj.label, frame_locked=False)
        p, o = m.pose.position, m.pose.orientation
        p.x, p.y, p.z = (float(v) for v in obj.position)
        o.x, o.y, o.z, o.w = (float(v) for v in obj.orientation)
        m.scale.x = m.scale.y = m.scale.z = float(obj.size)
        m.color.r, m.color.g, m.color.b, m.color.a = (float(v) for v in obj.rgba)
        markers.append(m)
    return MarkerArray(markers=markers)


def grasp_result(hdr: Header, event: TaskEvent, desired_object: str = '',
                 task_trial: int = 0) -> GraspResult:
    """GraspResult of a task event (durations in s, heights in m); ``trial`` is the task's trial
    (``/task/target``) when one is set (> 0), else the simulator's count of resets."""
    return GraspResult(header=hdr, trial=task_trial or event.trial, desired_object=desired_object,
                       grasped_object=event.grasped_object, success=event.success,
                       duration=float(event.duration), lift_height=float(event.lift_height),
                       reason=event.reason)


def status(hdr: Header, ok: bool, message: str, values: dict[str, object]) -> DiagnosticArray:
    """A one-entry DiagnosticArray named ``sim`` (level OK or WARN) with ``values`` as text."""
    level = DiagnosticStatus.OK if ok else DiagnosticStatus.WARN
    item = DiagnosticStatus(level=level, name='sim', message=message, hardware_id='pybullet',
                            values=[KeyValue(key=k, value=str(v)) for k, v in values.items()])
    return DiagnosticArray(header=hdr, status=[item])


def tf_message(time_msg: Time, transforms: list[Transform]) -> TFMessage:
    """tf2_msgs/TFMessage: one TransformStamped (parent -> child, m, quaternion xyzw) each."""
    out = []
    for t in transforms:
        msg = TransformStamped(header=Header(stamp=time_msg, frame_id=t.parent),
                               child_frame_id=t.child)
        tr, q = msg.transform.translation, msg.transform.rotation
        tr.x, tr.y, tr.z = (float(v) for v in t.translation)
        q.x, q.y, q.z, q.w = (float(v) for v in t.rotation)
        out.append(msg)
    return TFMessage(transforms=out)
