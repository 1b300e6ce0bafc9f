"""Vision node: colour detections, object of interest, AR overlay and depth shape of each frame.

Run::

    python -m mindgrasp_vision.vision_node --ros-args \
        --params-file config/param/vision.yaml

Subscribes /camera/color/image_raw (rgb8), /camera/depth/image_raw (32FC1 m), /camera/color/
camera_info, /bci/prediction (a left/right hand prediction shifts the ranking focus) and /fsm/state
(shapes are classified in ``classify_states``); publishes /vision/detections and /vision/overlay.
Service ``~/classify_shape`` (std_srvs/Trigger) classifies the current object of interest now.
The algorithms are :class:`mindgrasp_vision.pipeline.VisionPipeline`.
"""

from __future__ import annotations

import threading

from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import (
    Detection,
    DetectionArray,
    FsmState,
    MIPrediction,
)
from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, Image, RegionOfInterest
from mindgrasp_ros.interfaces.std_srvs.srv import Trigger

from mindgrasp_common.errors import CommonError
from mindgrasp_ros import rclpy
from mindgrasp_ros.image_bridge import cv2_to_imgmsg
from mindgrasp_ros.node_main import declare_duration, run_node
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import (
    BCI_PREDICTION,
    COLOR_IMAGE,
    COLOR_INFO,
    DEPTH_IMAGE,
    FSM_STATE,
    VISION_DETECTIONS,
    VISION_OVERLAY,
)
from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.detector import CameraModel
from mindgrasp_vision.params import VisionConfig
from mindgrasp_vision.ros_conversions import (
    depth_from_image,
    detection_to_msg,
    rgb_from_image,
)


def _stamp_ns(header: object) -> int:
    return rclpy.time.Time.from_msg(header.stamp).nanoseconds


class VisionNode(rclpy.node.Node):
    """Thin ROS wrapper round :class:`VisionPipeline` (parameters: param/vision.yaml)."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__('vision', **kwargs)
        # callbacks may run on several threads (composition uses a MultiThreadedExecutor)
        self._lock = threading.RLock()
        self.params = declare_params(self, VisionConfig, on_change=self.apply_parameters)
        classifier = None
        try:
            classifier = self.params.load_classifier()
        except VisionError as exc:
            self.get_logger().error(f'{exc} Running without shape classification.')
        self.pipeline = self.params.build_pipeline(classifier)
        self.detections_pub = self.create_publisher(DetectionArray, VISION_DETECTIONS.name,
                                                    VISION_DETECTIONS.qos)
        self.overlay_pub = self.create_publisher(Image, VISION_OVERLAY.name, VISION_OVERLAY.qos)
        self.create_subscription(Image, COLOR_IMAGE.name, self.color_callback, COLOR_IMAGE.qos)
        self.create_subscription(Image, DEPTH_IMAGE.name, self.depth_callback, DEPTH_IMAGE.qos)
        self.create_subscription(CameraInfo, COLOR_INFO.name, self.info_callback, COLOR_INFO.qos)
        self.create_subscription(MIPrediction, BCI_PREDICTION.name, self.prediction_callback,
                                 BCI_PREDICTION.qos)
        self.create_subscription(FsmState, FSM_STATE.name, self.state_callback, FSM_STATE.qos)
        self.create_service(Trigger, '~/classify_shape', self.classify_callback)
        self._pending = None      # (stamp ns, rgb, header) waiting for its depth image
        self._depth = None        # (stamp ns, depth)
        self._seen_depth = False
        self._mi = None           # (class index, receipt ROS time s)
        self._fsm_state = 0
        self._last = None         # (rgb, header, depth) of the last processed frame
        self.frames = 0
        self.done = rclpy.task.Future()
        self._last_image: float | None = None   # ROS time (s); set on the first watch tick
        self.create_timer(0.5, self.watch_callback)
        declare_duration(self)
        self.get_logger().info(
            f'Vision ready: colours {self.params.colour_names}, shape model '
            f'{"none" if classifier is None else self.params.shape_model}.')

    # ------------------------------------------------------------------ callbacks
    def color_callback(self, msg: Image) -> None:
        self._last_image = self._now()
        try:
            rgb = rgb_from_image(msg)
            self._check_size(rgb.shape[1], rgb.shape[0], COLOR_IMAGE.name)
        except VisionError as exc:
            self.get_logger().error(str(exc), throttle_duration_sec=5.0)
            return
        with self._lock:
            if self._pending is not None:
                # its depth image never came: process the older frame without depth
                self._process(*self._pending[1:], None)
            self._pending = (_stamp_ns(msg.header), rgb, msg.header)
            self._try_process()

    def depth_callback(self, msg: Image) -> None:
        try:
            depth = depth_from_image(msg)
            self._check_size(depth.shape[1], depth.shape[0], DEPTH_IMAGE.name)
        except VisionError as exc:
            self.get_logger().error(str(exc), throttle_duration_sec=5.0)
            return
        with self._lock:
            self._seen_depth = True
            self._depth = (_stamp_ns(msg.header), depth)
            self._try_process()

    def info_callback(self, msg: CameraInfo) -> None:
        try:
            self.pipeline.detector.intrinsics = CameraModel.from_k(msg.width, msg.height, msg.k)
        except CommonError as exc:
            self.get_logger().error(str(exc), throttle_duration_sec=5.0)

    def prediction_callback(self, msg: MIPrediction) -> None:
        self._mi = (int(msg.class_index), self._now())

    def state_callback(self, msg: FsmState) -> None:
        if msg.state == FsmState.RETURN_TO_START and self._fsm_state != msg.state:
            self.pipeline.reset()  # a new trial: forget the object of interest and its shape
        self._fsm_state = int(msg.state)

    def classify_callback(self, request: Trigger.Request, response: Trigger.Response
                          ) -> Trigger.Response:
        if self._last is None:
            response.success, response.message = False, 'No camera frame received yet.'
            return response
        if self.pipeline.classifier is None:
            response.success = False
            response.message = 'No shape model loaded; set the shape_model parameter.'
            return response
        with self._lock:
            result = self._process(*self._last, classify=True)
        target = None if result is None else result.target
        if target is None or target.shape == 'unknown':
            response.success, response.message = False, 'No object of interest to classify.'
        else:
            response.success = True
            response.message = f'{target.label} {target.shape_confidence:.3f}'
        return response

    def apply_parameters(self, cfg: VisionConfig, names: set[str]) -> None:
        """A live change: rebuild the detector and ranker (a VisionError refuses the change)."""
        detector, ranker = cfg.build_detector(), cfg.build_ranker()
        with self._lock:
            detector.intrinsics = self.pipeline.detector.intrinsics
            self.pipeline.detector, self.pipeline.ranker = detector, ranker
            self.pipeline.shape_min_fraction = float(cfg.shape_min_fraction)
            self.pipeline.shape_max_fraction = float(cfg.shape_max_fraction)

    def watch_callback(self) -> None:
        now = self._now()
        if self._last_image is None or now < self._last_image:  # start, or sim time reset
            self._last_image = now
        silent = now - self._last_image
        if 0 < self.params.image_timeout < silent:
            self.get_logger().error(f'No camera image on {COLOR_IMAGE.name} for {silent:.1f} s; '
                                    'check that the camera driver or the simulator is running '
                                    'and publishing rgb8 images.', throttle_duration_sec=5.0)

    # ------------------------------------------------------------------ work
    def _now(self) -> float:
        """ROS time (s): simulated time under use_sim_time, so timeouts scale with the sim."""
        return self.get_clock().now().nanoseconds * 1e-9

    def _check_size(self, width: int, height: int, topic: str) -> None:
        ew, eh = int(self.params.expected_width), int(self.params.expected_height)
        if (ew and width != ew) or (eh and height != eh):
            msg = (f'The image on {topic} is {width}x{height} px, expected {ew or width}x'
                   f'{eh or height} px (parameters expected_width/expected_height); fix the '
                   'camera resolution or the parameters.')
            raise VisionError(msg)

    def _try_process(self) -> None:
        if self._pending is None:
            return
        stamp, rgb, header = self._pending
        tol = int(self.params.sync_tolerance * 1e9)
        if self._depth is not None and abs(self._depth[0] - stamp) <= tol:
            depth = self._depth[1]
        elif self._seen_depth and (self._depth is None or self._depth[0] < stamp - tol):
            return  # the matching depth image is still on its way
        else:
            depth = None
        self._pending = None
        self._process(rgb, header, depth)

    def _process(self, rgb: object, header: object, depth: object, classify: bool = False):
        if depth is not None and depth.shape != rgb.shape[:2]:
            self.get_logger().error(f'The depth image is {depth.shape[1]}x{depth.shape[0]} px '
                                    f'but the colour image is {rgb.shape[1]}x{rgb.shape[0]} px; '
                                    'publish the depth registered to the colour camera.',
                                    throttle_duration_sec=5.0)
            depth = None
        mi = None
        if self._mi is not None and self._now() - self._mi[1] <= self.params.prediction_timeout:
            mi = self._mi[0]
        classify = classify or self._fsm_state in list(self.params.classify_states)
        try:
            result = self.pipeline.process(rgb, depth, mi, classify=classify)
        except VisionError as exc:
            self.get_logger().error(str(exc), throttle_duration_sec=5.0)
            return None
        self._last = (rgb, header, depth)
        self.frames += 1
        out = DetectionArray(
            header=header, image_width=result.width, image_height=result.height,
            object_of_interest=-1 if result.object_of_interest is None
            else result.object_of_interest,
            detections=[detection_to_msg(Detection, RegionOfInterest, d)
                        for d in result.detections])
        self.detections_pub.publish(out)
        if self.params.publish_overlay:
            self.overlay_pub.publish(cv2_to_imgmsg(self.pipeline.overlay(rgb, result), 'rgb8',
                                                   header))
        return result

    def destroy_node(self) -> None:
        self.get_logger().info(f'Vision processed {self.frames} frames.')
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the vision node until Ctrl-C or the ``duration`` parameter."""
    return run_node(VisionNode, args, errors=(VisionError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
