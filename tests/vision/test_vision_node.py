"""The vision node in its own process, over real DDS, fed with rendered simulator frames."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from mindgrasp_common.resources import resource_path
from mindgrasp_ros.image_bridge import cv2_to_imgmsg

pytestmark = pytest.mark.slow

PARAMS = str(resource_path('mindgrasp_vision', 'param', 'vision.yaml'))


def _spin_until(rclpy, node, predicate, timeout: float) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        rclpy.spin_once(node, timeout_sec=0.05)
    return predicate()


class Camera:
    """Test-side node: publishes camera frames and predictions, records the vision output."""

    def __init__(self, rclpy) -> None:
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import (
            DetectionArray,
            FsmState,
            MIPrediction,
        )
        from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, Image

        self.rclpy = rclpy
        self.node = rclpy.node.Node('vision_test_camera')
        sensor = rclpy.qos.qos_profile_sensor_data
        self.color = self.node.create_publisher(Image, '/camera/color/image_raw', sensor)
        self.depth = self.node.create_publisher(Image, '/camera/depth/image_raw', sensor)
        self.info = self.node.create_publisher(CameraInfo, '/camera/color/camera_info', sensor)
        self.prediction = self.node.create_publisher(MIPrediction, '/bci/prediction', 10)
        state_qos = rclpy.qos.QoSProfile(
            depth=1, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
            durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
        self.state = self.node.create_publisher(FsmState, '/fsm/state', state_qos)
        self.detections: list = []
        self.stamps: set = set()
        self.overlays: list = []
        self.node.create_subscription(DetectionArray, '/vision/detections',
                                      self.detections.append, 10)
        self.node.create_subscription(Image, '/vision/overlay', self.overlays.append, sensor)
        self._types = (Image, CameraInfo, MIPrediction, FsmState)

    def publish(self, rgb: np.ndarray, depth: np.ndarray | None, k: np.ndarray,
                encoding: str = 'rgb8') -> object:
        image_cls, info_cls, _, _ = self._types
        header = image_cls().header
        header.stamp = self.node.get_clock().now().to_msg()
        header.frame_id = 'camera_color_optical_frame'
        h, w = rgb.shape[:2]
        self.info.publish(info_cls(header=header, height=h, width=w, k=k.ravel()))
        if depth is not None:
            dh, dw = depth.shape
            self.depth.publish(image_cls(
                header=header, height=dh, width=dw, encoding='32FC1', step=dw * 4,
                data=np.frombuffer(depth.astype('<f4').tobytes(), np.uint8)))
        msg = cv2_to_imgmsg(rgb, 'rgb8', header)
        msg.encoding = encoding
        self.stamps.add((header.stamp.sec, header.stamp.nanosec))
        self.color.publish(msg)
        return header.stamp

    def stream(self, rgb, depth, k, until, timeout: float = 60.0, mi_class: int | None = None,
               **kwargs) -> bool:
        """Publish the frame (and the MI prediction, if given) at about 10 Hz until ``until()``."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if mi_class is not None:
                self.predict(mi_class)
            self.publish(rgb, depth, k, **kwargs)
            if _spin_until(self.rclpy, self.node, until, 0.1):
                return True
        return until()

    def predict(self, class_index: int) -> None:
        pred_cls = self._types[2]
        self.prediction.publish(pred_cls(class_index=class_index, certainty=1.0,
                                         class_names=['left_hand', 'right_hand', 'both_hands',
                                                      'both_feet']))

    def set_state(self, state: int) -> None:
        self.state.publish(self._types[3](state=state))


def _target(msg) -> object:
    return None if msg.object_of_interest < 0 else msg.detections[msg.object_of_interest]


def test_detections_overlay_focus_shift_and_shape(rclpy_ctx, spawn_node, sim, view):
    k, _, _ = sim.camera_intrinsics()
    three = view([{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.12]},
                  {'shape': 'sphere', 'colour': 'yellow', 'position': [0.45, 0.0]},
                  {'shape': 'cylinder', 'colour': 'blue', 'position': [0.45, -0.12]}],
                 (0.45, 0.0, 0.025), distance=0.4, elevation_deg=45)
    close = view([{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.0]}],
                 (0.45, 0.0, 0.025), distance=0.17, elevation_deg=55)
    proc = spawn_node('mindgrasp_vision.vision_node', '--ros-args', '--params-file', PARAMS,
                      '-p', 'duration:=300.0', '-p', 'switch_frames:=2')
    assert proc.wait_for_output('Vision ready', 60.0), proc.output()
    assert 'shape model none' not in proc.output()
    cam = Camera(rclpy_ctx)
    assert cam.stream(*three, k, lambda: len(cam.detections) >= 3 and cam.overlays), \
        proc.output()
    msg = cam.detections[-1]
    assert (msg.image_width, msg.image_height) == (128, 128)
    assert msg.header.frame_id == 'camera_color_optical_frame'   # the image's header
    assert (msg.header.stamp.sec, msg.header.stamp.nanosec) in cam.stamps
    assert sorted(d.colour for d in msg.detections) == ['blue', 'red', 'yellow']
    assert _target(msg).colour == 'yellow' and _target(msg).is_object_of_interest
    assert all(0.3 < d.distance < 0.5 for d in msg.detections)
    overlay = cam.overlays[-1]
    assert (overlay.encoding, overlay.width, overlay.height) == ('rgb8', 128, 128)
    img = np.asarray(overlay.data).reshape(128, 128, 3)
    assert np.all(img == (0, 255, 0), axis=2).sum() > 40        # the green box
    # the user imagines the left hand: the focus moves left, so does the object of interest
    assert cam.stream(*three, k, lambda: _target(cam.detections[-1]).colour == 'red',
                      mi_class=0), [_target(m).colour for m in cam.detections[-10:]]
    # close to one object: the shape CNN names it
    assert cam.stream(*close, k, lambda: _target(cam.detections[-1]).shape != 'unknown')
    target = _target(cam.detections[-1])
    assert (target.colour, target.shape) == ('red', 'cube') and target.shape_confidence > 0.5
    # and on request, through the service
    from mindgrasp_ros.interfaces.std_srvs.srv import Trigger

    client = cam.node.create_client(Trigger, '/vision/classify_shape')
    assert client.wait_for_service(timeout_sec=60.0)
    future = client.call_async(Trigger.Request())
    assert _spin_until(rclpy_ctx, cam.node, future.done, 60.0)
    assert future.result().success and future.result().message.startswith('red cube')
    assert proc.stop() == 0


def test_bad_images_are_reported_by_name(rclpy_ctx, spawn_node, sim, view):
    k, _, _ = sim.camera_intrinsics()
    rgb, depth = view([{'shape': 'cube', 'colour': 'blue', 'position': [0.45, 0.0]}],
                      (0.45, 0.0, 0.025), distance=0.3, elevation_deg=50)
    proc = spawn_node('mindgrasp_vision.vision_node', '--ros-args', '-p', 'shape_model:=none',
                      '-p', 'duration:=300.0', '-p', 'image_timeout:=1.0')
    assert proc.wait_for_output('Vision ready', 60.0), proc.output()
    # no camera yet: reported
    assert proc.wait_for_output('No camera image on /camera/color/image_raw', 60.0)
    cam = Camera(rclpy_ctx)
    # a mono8 image: nothing is published, the log names the encoding and the fix
    cam.stream(rgb, None, k, lambda: "encoding 'mono8'" in proc.output(), encoding='mono8')
    assert "encoding 'mono8', expected 'rgb8'" in proc.output()
    assert cam.detections == []
    # a depth image of another size: reported, colour detection goes on without depth
    small = np.ascontiguousarray(depth[::2, ::2])
    assert cam.stream(rgb, small, k, lambda: len(cam.detections) >= 2)
    assert proc.wait_for_output('The depth image is 64x64 px but the colour image is 128x128 px',
                                60), proc.output()
    assert [d.colour for d in cam.detections[-1].detections] == ['blue']
    # without usable depth the distance comes from the known object size (0.05 m), as the
    # paper did
    assert 0.15 < cam.detections[-1].detections[0].distance < 0.5
    assert proc.stop() == 0


def test_images_of_an_unexpected_size_are_rejected(rclpy_ctx, spawn_node, sim, view):
    k, _, _ = sim.camera_intrinsics()
    rgb, depth = view([{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.0]}],
                      (0.45, 0.0, 0.025), distance=0.3, elevation_deg=50)
    proc = spawn_node('mindgrasp_vision.vision_node', '--ros-args', '-p', 'shape_model:=none',
                      '-p', 'expected_width:=640', '-p', 'expected_height:=480',
                      '-p', 'duration:=120.0')
    assert proc.wait_for_output('Vision ready', 60.0), proc.output()
    cam = Camera(rclpy_ctx)
    text = 'The image on /camera/color/image_raw is 128x128 px, expected 640x480 px'
    assert cam.stream(rgb, depth, k, lambda: text in proc.output())
    assert cam.detections == []
    assert proc.stop() == 0


def test_with_the_simulator_node(rclpy_ctx, spawn_node):
    """sim_node -> vision_node -> this process: the home view of the set_locations scene."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray

    # durations well beyond the wait: a loaded machine may take long to start both processes
    sim = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'scene:=set_locations',
                     '-p', 'duration:=180.0')
    vision = spawn_node('mindgrasp_vision.vision_node', '--ros-args', '--params-file', PARAMS,
                        '-p', 'duration:=180.0')
    node = rclpy_ctx.node.Node('vision_test_listener')
    got: list = []
    node.create_subscription(DetectionArray, '/vision/detections', got.append, 10)
    # a colour frame whose depth image was lost (best effort, loaded host) is processed without
    # depth: its distances are NaN ("unknown", Detection.msg). Wait for a frame with depth.
    def with_depth() -> bool:
        return len(got) >= 3 and bool(got[-1].detections) and \
            all(math.isfinite(d.distance) for d in got[-1].detections)

    assert _spin_until(rclpy_ctx, node, with_depth, 120.0), \
        sim.output()[-2000:] + vision.output()[-2000:]
    msg = got[-1]
    by_x = sorted(msg.detections, key=lambda d: d.centre_x)
    assert [d.colour for d in by_x] == ['blue', 'red', 'yellow']
    assert _target(msg).colour == 'red'    # straight ahead: the red cube
    assert all(0.4 < d.distance < 0.8 for d in msg.detections), \
        [[d.distance for d in m.detections] for m in got]
    assert vision.stop() == 0
