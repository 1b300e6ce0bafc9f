"""The fsm node in its own process, over real DDS: commands, state topic, watchdog."""

from __future__ import annotations

import time

import numpy as np
import pytest

from mindgrasp_testing import spin_until

from .conftest import publish_left_hand

pytestmark = pytest.mark.slow

HOME = [0.0, 0.0, 0.0, np.pi / 2, 1.2, 0.0]


def test_fsm_node_turns_on_left_hand_and_stops_when_predictions_end(rclpy_ctx, spawn_node
                                                                    ) -> None:
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, FsmState, MIPrediction
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
    from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

    proc = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'duration:=300.0',
                      '-p', 'lock_duration:=0.5', '-p', 'search_gain:=0.4',
                      '-p', 'paradigm:=paper')
    assert proc.wait_for_output('Grasp controller ready', 60.0), proc.output()

    node = rclpy.node.Node('fsm_test_driver')
    commands: list[np.ndarray] = []
    states: list[object] = []
    node.create_subscription(Float64MultiArray, '/arm_controller/commands',
                             lambda m: commands.append(np.array(m.data)), 10)
    latched = rclpy.qos.QoSProfile(depth=1, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                                   durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(FsmState, '/fsm/state', states.append, latched)
    js_pub = node.create_publisher(JointState, '/joint_states', 10)
    det_pub = node.create_publisher(DetectionArray, '/vision/detections', 10)
    pred_pub = node.create_publisher(MIPrediction, '/bci/prediction', 10)

    # nothing published yet: the controller holds still and says why
    assert spin_until(node, lambda: any(s.stopped for s in states), 60.0), proc.output()
    assert 'no joint states' in next(s for s in states if s.stopped).reason
    # waiting for a first input is how every start begins: said as information, not a warning
    assert proc.wait_for_output('no joint states received yet', 60.0), proc.output()
    waiting = [line for line in proc.output().splitlines() if 'received yet' in line]
    assert waiting and all('[INFO]' in line for line in waiting), waiting

    send_predictions = [True]

    def publish() -> None:
        stamp = node.get_clock().now().to_msg()
        js = JointState(name=[f'joint_{i}' for i in range(1, 7)], position=np.array(HOME),
                        velocity=np.zeros(6))
        js.header.stamp = stamp
        js_pub.publish(js)
        publish_left_hand(node, det_pub, pred_pub, send_predictions[0])

    node.create_timer(0.05, publish)
    # left-hand imagery in Object Search turns joint 1 left at search_gain * certainty
    assert spin_until(node, lambda: bool(commands) and abs(commands[-1][0] - 0.4) < 1e-9, 60.0), \
        (commands[-3:], proc.output())
    assert np.all(commands[-1][1:] == 0)
    # /fsm/state is another topic: its "running" message may arrive after the first command
    assert spin_until(node, lambda: not states[-1].stopped, 60.0), \
        ([(s.state, s.reason) for s in states[-3:]], proc.output())
    assert states[-1].state == FsmState.OBJECT_SEARCH

    # predictions stop: the watchdog (0.3 s) commands every joint to 0 and the state says why.
    # Commands and states are two topics: wait for each condition on its own topic, never on
    # the order in which they arrive.
    send_predictions[0] = False
    assert spin_until(node, lambda: states[-1].stopped, 60.0), proc.output()
    assert 'MI prediction' in states[-1].reason
    assert spin_until(node, lambda: bool(np.all(commands[-1] == 0)), 60.0), commands[-3:]
    n = len(commands)
    assert spin_until(node, lambda: len(commands) > n + 5, 60.0)
    assert all(np.all(c == 0) for c in commands[n - 1:])   # and it stays stopped
    # stopped, the state is published on change and at most once per second (its reason
    # carries a changing age): an upper bound, which a loaded machine can only lower
    k = len(states)
    t0 = time.monotonic()
    spin_until(node, lambda: False, 3.0)
    assert len(states) - k <= (time.monotonic() - t0) + 2, [s.reason for s in states[k:]]

    # the EEG comes back, still decoding left hand: the arm does not start by itself
    # (resume_after_stale: require_new_command) until one class was held for resume_hold (1 s)
    n = len(commands)
    send_predictions[0] = True
    assert spin_until(node, lambda: 'waiting for a new command' in states[-1].reason, 60.0), \
        [s.reason for s in states[-3:]]
    assert all(np.all(c == 0) for c in commands[n:])
    assert spin_until(node, lambda: not states[-1].stopped, 60.0), proc.output()
    assert spin_until(node, lambda: abs(commands[-1][0] - 0.4) < 1e-9, 60.0)
    # its log line and the command are written in one tick, in no fixed order: wait for it
    assert proc.wait_for_output('fresh decision after the prediction loss: left hand', 60), \
        proc.output()
    node.destroy_node()
    assert proc.stop() in (0, -2, 130), proc.output()


def test_node_graph_sim_vision_fsm_selects_and_approaches(rclpy_ctx, spawn_node) -> None:
    """sim_node + vision_node + fsm_node (autonomous), each its own process: the controller sees
    the red cube ahead through the real camera topics, centres it and starts the approach."""
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState

    sim = spawn_node('mindgrasp_sim.sim_node', '--ros-args', '-p', 'scene:=set_locations',
                     '-p', 'duration:=300.0')
    vision = spawn_node('mindgrasp_vision.vision_node', '--ros-args', '-p', 'shape_model:=none')
    fsm = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'autonomous:=true',
                     '-p', 'duration:=300.0')
    node = rclpy.node.Node('fsm_graph_observer')
    states: list[object] = []
    latched = rclpy.qos.QoSProfile(depth=1, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                                   durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(FsmState, '/fsm/state', states.append, latched)
    ok = spin_until(node, lambda: any(s.state == FsmState.INITIAL_APPROACH for s in states),
                    180.0)
    assert ok, ([(s.state, s.reason) for s in states[-5:]], fsm.output()[-2000:],
                vision.output()[-1000:], sim.output()[-1000:])
    entered = next(s for s in states if s.state == FsmState.INITIAL_APPROACH)
    assert entered.object_of_interest.startswith('red')
    assert entered.previous_state == FsmState.CENTER_OBJECT
    node.destroy_node()


def _mindgrasp(*args: str):
    import subprocess
    import sys

    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=120)


def test_fsm_parameters_live_change_refusal_and_read_only(rclpy_ctx, spawn_node) -> None:
    """`mindgrasp param set /fsm watchdog_timeout -1` is refused with the range; a valid value
    takes effect in the running controller; the robot model is read-only."""
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState

    from mindgrasp_ros.topics import FSM_STATE, JOINT_STATES

    proc = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'duration:=300.0')
    assert proc.wait_for_output('Grasp controller ready', 60.0), proc.output()
    out = _mindgrasp('param', 'describe', '/fsm', 'watchdog_timeout', 'urdf_file')
    assert out.returncode == 0, out.stderr
    assert 'Description: oldest acceptable prediction / joint state; older inputs stop every ' \
        'joint [s]' in out.stdout and 'Min value: 0.01\n    Max value: 10.0' in out.stdout
    assert 'Parameter name: urdf_file\n  Type: string' in out.stdout
    out = _mindgrasp('param', 'set', '/fsm', 'watchdog_timeout', '-1')
    assert out.returncode == 1, out.stdout
    assert 'Setting parameter failed' in out.stderr and 'must be within [0.01, 10.0]' in out.stderr
    out = _mindgrasp('param', 'set', '/fsm', 'urdf_file', '/tmp/other.urdf')
    assert out.returncode == 1 and "'urdf_file' is read-only" in out.stderr, out.stderr

    node = rclpy.node.Node('fsm_param_driver')
    states: list[object] = []
    node.create_subscription(FsmState, FSM_STATE.name, states.append, FSM_STATE.qos)
    js_pub = node.create_publisher(JointState, JOINT_STATES.name, JOINT_STATES.qos)
    assert spin_until(node, lambda: js_pub.get_subscription_count() > 0, 60.0)
    js = JointState(name=[f'joint_{i}' for i in range(1, 7)], position=np.array(HOME),
                    velocity=np.zeros(6))
    js.header.stamp = node.get_clock().now().to_msg()
    js_pub.publish(js)   # once: the joint states then grow old
    assert spin_until(node, lambda: bool(states) and 'limit 0.30 s' in states[-1].reason, 60.0), \
        ([s.reason for s in states[-3:]], proc.output())
    out = _mindgrasp('param', 'set', '/fsm', 'watchdog_timeout', '1.5')
    assert out.returncode == 0 and 'Set parameter successful' in out.stdout, out.stderr
    assert spin_until(node, lambda: 'limit 1.50 s' in states[-1].reason, 60.0), \
        ([s.reason for s in states[-3:]], proc.output())
    assert _mindgrasp('param', 'get', '/fsm', 'watchdog_timeout').stdout.strip() == \
        'Double value is: 1.5'
    node.destroy_node()
    assert proc.stop() == 0, proc.output()


def test_fsm_bad_parameter_refuses_to_start(spawn_node) -> None:
    proc = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'recenter_threshold:=0.01')
    assert proc.wait(60) == 2
    out = proc.output()
    assert "'recenter_threshold' (0.01) must exceed 'center_tolerance'" in out, out
    assert 'Traceback' not in out


def test_nan_joint_states_from_a_second_publisher_latch_a_stop(rclpy_ctx, spawn_node) -> None:
    """Issue 31, item 6: beside the arm driver's clean joint states (50 Hz) a second publisher
    sends NaN ones at 20 Hz. The controller used to alternate stop and move (20 times in 3.2 s);
    now the first NaN latches a stop (one warning line) that holds while the NaN publisher runs,
    is released (one line) once the joint states were clean for sensor_clean_time, and the arm
    moves again only after a fresh decision."""
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import DetectionArray, MIPrediction
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
    from mindgrasp_ros.interfaces.std_msgs.msg import Float64MultiArray

    proc = spawn_node('mindgrasp_fsm.fsm_node', '--ros-args', '-p', 'duration:=300.0',
                      '-p', 'search_gain:=0.4', '-p', 'paradigm:=paper')
    assert proc.wait_for_output('Grasp controller ready', 60.0), proc.output()
    node = rclpy.node.Node('fsm_fault_driver')
    faulty = rclpy.node.Node('nan_joint_states')     # the second publisher, its own node
    commands: list[np.ndarray] = []
    node.create_subscription(Float64MultiArray, '/arm_controller/commands',
                             lambda m: commands.append(np.array(m.data)), 100)
    js_pub = node.create_publisher(JointState, '/joint_states', 10)
    nan_pub = faulty.create_publisher(JointState, '/joint_states', 10)
    det_pub = node.create_publisher(DetectionArray, '/vision/detections', 10)
    pred_pub = node.create_publisher(MIPrediction, '/bci/prediction', 10)
    names = [f'joint_{i}' for i in range(1, 7)]

    def publish() -> None:
        stamp = node.get_clock().now().to_msg()
        js = JointState(name=names, position=np.array(HOME), velocity=np.zeros(6))
        js.header.stamp = stamp
        js_pub.publish(js)
        det = DetectionArray(image_width=128, image_height=128, object_of_interest=-1)
        det.header.stamp = stamp
        det_pub.publish(det)
        pred = MIPrediction(class_index=MIPrediction.LEFT_HAND, certainty=1.0)
        pred.header.stamp = stamp
        pred_pub.publish(pred)

    nan_sent = [0]
    sending = [False]

    def publish_nan() -> None:
        if sending[0]:
            js = JointState(name=names, position=np.full(6, np.nan), velocity=np.zeros(6))
            js.header.stamp = faulty.get_clock().now().to_msg()
            nan_pub.publish(js)
            nan_sent[0] += 1

    node.create_timer(0.02, publish)
    faulty.create_timer(0.05, publish_nan)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    executor.add_node(faulty)

    def spin(predicate, timeout: float = 60.0) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline and not predicate():
            executor.spin_once(timeout_sec=0.02)
        return predicate()

    assert spin(lambda: bool(commands) and abs(commands[-1][0] - 0.4) < 1e-9), proc.output()
    # (a start-up hiccup of this test's publishers may have latched and released once already)
    latches = proc.output().count('sensor fault:')
    sending[0] = True
    assert spin(lambda: 'sensor fault: joint states contain NaN' in proc.output()), \
        proc.output()
    assert spin(lambda: bool(np.all(commands[-1] == 0)))
    n = len(commands)
    assert spin(lambda: nan_sent[0] >= 40)            # 2 s of NaN at 20 Hz
    assert all(np.all(c == 0) for c in commands[n:]), 'moved while the NaN publisher ran'
    assert proc.output().count('sensor fault:') == latches + 1, proc.output()
    # the NaN publisher stops: released after 1 s clean, then a fresh decision (1 s of left
    # hand decoded after the release) restarts the arm
    sending[0] = False
    released = proc.output().count('sensor fault released')
    assert spin(lambda: proc.output().count('sensor fault released') > released), proc.output()
    assert all(np.all(c == 0) for c in commands[n:])
    assert spin(lambda: abs(commands[-1][0] - 0.4) < 1e-9), proc.output()
    assert spin(lambda: proc.output().count('fresh decision after the sensor fault: left hand')
                > released), proc.output()
    executor.shutdown()
    faulty.destroy_node()
    node.destroy_node()
    assert proc.stop() in (0, -2, 130), proc.output()
