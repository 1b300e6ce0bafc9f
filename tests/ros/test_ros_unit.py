"""mindgrasp_ros in one process: type support, CDR against rosbags, RIHS01, names, arguments,
parameters, sim time, composition and lock-step, malformed samples, error messages."""

from __future__ import annotations

import time

import numpy as np
import pytest
import yaml
from rosbags.typesys import Stores, get_typestore

from mindgrasp_ros import typesupport
from mindgrasp_ros.runtime.arguments import ParamsFileError, parse_ros_args
from mindgrasp_ros.runtime.exceptions import InvalidNameError
from mindgrasp_ros.runtime.names import expand_topic_name, validate_topic_name
from mindgrasp_testing import spin_until

# every message type the MIndGrasp graph puts on the wire
GRAPH_TYPES = [
    'mindgrasp_msgs/msg/EEGChunk', 'mindgrasp_msgs/msg/MIPrediction', 'mindgrasp_msgs/msg/Prompt',
    'mindgrasp_msgs/msg/Detection', 'mindgrasp_msgs/msg/DetectionArray',
    'mindgrasp_msgs/msg/FsmState', 'mindgrasp_msgs/msg/TaskTarget',
    'mindgrasp_msgs/msg/GraspResult', 'mindgrasp_msgs/msg/EEGMarker', 'sensor_msgs/msg/Image',
    'sensor_msgs/msg/CameraInfo',
    'sensor_msgs/msg/JointState', 'std_msgs/msg/Float64MultiArray', 'std_msgs/msg/String',
    'geometry_msgs/msg/PoseStamped', 'visualization_msgs/msg/MarkerArray',
    'diagnostic_msgs/msg/DiagnosticArray', 'rosgraph_msgs/msg/Clock', 'rcl_interfaces/msg/Log',
    'rcl_interfaces/msg/ParameterEvent', 'rmw_dds_common/msg/ParticipantEntitiesInfo',
]


def _random_message(typename: str, rng: np.random.Generator, depth: int = 0):
    """A message of ``typename`` with every field filled with seeded random content."""
    cls = typesupport.get_message_class(typename)
    msg = cls()
    store = typesupport.typestore()
    for name, desc in store.fielddefs[typename][1]:
        value = getattr(msg, name)
        if isinstance(value, np.ndarray):
            n = value.shape[0] if value.shape[0] else int(rng.integers(0, 7))
            if value.dtype == np.bool_:
                setattr(msg, name, rng.integers(0, 2, n).astype(bool))
            elif value.dtype.kind == 'f':
                setattr(msg, name, rng.normal(size=n).astype(value.dtype))
            else:
                info = np.iinfo(value.dtype)
                setattr(msg, name, rng.integers(max(info.min, -1000), min(info.max, 1000), n,
                                                dtype=value.dtype))
        elif isinstance(value, bool):
            setattr(msg, name, bool(rng.integers(0, 2)))
        elif isinstance(value, int):
            setattr(msg, name, int(rng.integers(0, 200)))
        elif isinstance(value, float):
            setattr(msg, name, float(rng.normal()))
        elif isinstance(value, str):
            setattr(msg, name, 'x' * int(rng.integers(0, 9)))
        elif isinstance(value, list) and depth < 3:
            _kind, detail = desc
            inner = detail[0]
            if inner[0].name == 'NAME':
                setattr(msg, name, [_random_message(inner[1], rng, depth + 1)
                                    for _ in range(int(rng.integers(0, 3)))])
            elif (value and isinstance(value[0], str)) or inner[1][0] == 'string':
                n = len(value) if value else int(rng.integers(0, 4))
                setattr(msg, name, [f's{i}' for i in range(n)])
        elif hasattr(value, '__msgtype__') and depth < 3:
            setattr(msg, name, _random_message(value.__msgtype__, rng, depth + 1))
    return msg


def _to_rosbags(msg, store):
    """The same message as a rosbags dataclass (the reference implementation)."""
    cls = store.types[msg.__msgtype__]
    values = []
    for name in msg._fields:
        v = getattr(msg, name)
        if hasattr(v, '__msgtype__'):
            v = _to_rosbags(v, store)
        elif isinstance(v, list) and v and hasattr(v[0], '__msgtype__'):
            v = [_to_rosbags(x, store) for x in v]
        values.append(v)
    return cls(*values)


@pytest.mark.parametrize('typename', GRAPH_TYPES)
def test_cdr_is_byte_exact_with_rosbags(typename):
    reference = get_typestore(Stores.ROS2_JAZZY)
    if typename.startswith('mindgrasp_msgs/'):
        reference.register({k: v for k, v in typesupport.typestore().fielddefs.items()
                            if k.startswith('mindgrasp_msgs/msg/')})
    rng = np.random.default_rng(1234)
    for _ in range(5):
        msg = _random_message(typename, rng)
        ours = typesupport.serialize(msg)
        theirs = bytes(reference.serialize_cdr(_to_rosbags(msg, reference), typename))
        assert ours == theirs
        assert typesupport.serialize(typesupport.deserialize(ours, typename)) == ours


def test_rihs01_known_values():
    assert typesupport.rihs01('std_msgs/msg/String') == (
        'RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18')
    # has char fields (Gid): rosbags alone gets this one wrong
    assert typesupport.rihs01('rmw_dds_common/msg/ParticipantEntitiesInfo') == (
        'RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e')


def test_messages_behave_like_rclpy():
    from mindgrasp_ros.interfaces.geometry_msgs.msg import Quaternion
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState
    from mindgrasp_ros.interfaces.sensor_msgs.msg import CameraInfo, JointState

    js = JointState(name=['j1'], position=[0.5])
    assert js.position.dtype == np.float64 and js.position.tolist() == [0.5]
    assert Quaternion().w == 1.0
    assert CameraInfo().k.shape == (9,)
    assert FsmState.GRASP_OBJECT == 5
    assert 'position' in JointState.get_fields_and_field_types()
    with pytest.raises(TypeError, match="has no field 'pos'; its fields are"):
        JointState(pos=[1.0])
    with pytest.raises(ValueError, match='exactly 9 elements'):
        CameraInfo(k=[1.0, 2.0])
    with pytest.raises(ImportError, match="Unknown msg type 'sensor_msgs/msg/Nope'"):
        from mindgrasp_ros.interfaces.sensor_msgs.msg import Nope  # noqa: F401


def test_names_and_arguments(tmp_path):
    assert expand_topic_name('~/status', 'amp', '/eeg') == '/eeg/amp/status'
    assert expand_topic_name('raw', 'amp', '/eeg') == '/eeg/raw'
    with pytest.raises(InvalidNameError, match="part '2raw'"):
        validate_topic_name('/eeg/2raw')
    f = tmp_path / 'p.yaml'
    f.write_text('/**:\n  ros__parameters: {a: 1}\n/lab/amp:\n  ros__parameters:\n'
                 '    b: {c: x}\nother:\n  ros__parameters: {d: 2}\n')
    args = parse_ros_args(['prog', '--ros-args', '--params-file', str(f), '-p', 'a:=5',
                           '-p', 'amp:e:=[1, 2]', '-r', 'amp:x:=y', '--log-level', 'debug'])
    assert args.parameters_for('amp', '/lab') == {'a': 5, 'b.c': 'x', 'e': [1, 2]}
    assert args.parameters_for('other', '/') == {'a': 5, 'd': 2}
    assert args.remaps[0].node == 'amp'
    bad = tmp_path / 'bad.yaml'
    bad.write_text('node:\n  parameters: {a: 1}\n')
    with pytest.raises(ParamsFileError, match='must be a mapping of node names to'):
        parse_ros_args(['--ros-args', '--params-file', str(bad)])
    with pytest.raises(ParamsFileError, match='does not exist'):
        parse_ros_args(['--ros-args', '--params-file', str(tmp_path / 'missing.yaml')])
    with pytest.raises(Exception, match='Unknown ROS argument'):
        parse_ros_args(['--ros-args', '--bogus'])


def test_a_params_file_written_by_launch_ros_loads_and_nothing_unsafe_does(tmp_path):
    # what launch_ros (Jazzy) writes for Node(parameters=[{'wait_for': ['/a', '/b']}]): yaml.dump
    # of a dict whose lists it turned into tuples
    f = tmp_path / 'launch_params_x'
    f.write_text(yaml.dump({'/**': {'ros__parameters': {'wait_for': ('/a', '/b'), 'n': 2}}}))
    assert '!!python/tuple' in f.read_text()
    args = parse_ros_args(['--ros-args', '--params-file', str(f)])
    assert args.parameters_for('fsm', '/') == {'wait_for': ['/a', '/b'], 'n': 2}
    evil = tmp_path / 'evil.yaml'
    evil.write_text("/**:\n  ros__parameters:\n    a: !!python/object/apply:os.system ['true']\n")
    with pytest.raises(ParamsFileError, match='is not valid YAML'):
        parse_ros_args(['--ros-args', '--params-file', str(evil)])


def test_parameters_typed_and_callbacks(rclpy_ctx):
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import SetParametersResult

    node = rclpy.node.Node(
        'params', parameter_overrides=[rclpy.parameter.Parameter('gain', value=2)])
    assert node.declare_parameter('gain', 1.0).value == 2.0  # int override into a double
    node.declare_parameter('model', rclpy.parameter.Parameter.Type.STRING)
    with pytest.raises(rclpy.exceptions.ParameterUninitializedException, match='-p model:='):
        node.get_parameter('model')
    with pytest.raises(rclpy.exceptions.ParameterNotDeclaredException, match='not been declared'):
        node.get_parameter('nope')
    seen = []

    def check(params):
        seen.extend(p.name for p in params)
        ok = all(p.value > 0 for p in params if p.name == 'gain')
        return SetParametersResult(successful=ok, reason='' if ok else 'gain must be > 0')

    node.add_on_set_parameters_callback(check)
    P = rclpy.parameter.Parameter  # noqa: N806
    res = node.set_parameters([P('gain', value=-1.0), P('gain', value='x'), P('gain', value=3.0)])
    assert [r.successful for r in res] == [False, False, True]
    assert res[0].reason == 'gain must be > 0' and 'expected DOUBLE' in res[1].reason
    assert node.get_parameter('gain').value == 3.0
    node.destroy_node()


def test_timers_follow_sim_time(rclpy_ctx):
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.rosgraph_msgs.msg import Clock

    node = rclpy.node.Node('sim_timer', parameter_overrides=[
        rclpy.parameter.Parameter('use_sim_time', value=True)])
    clock_node = rclpy.node.Node('clock_source')
    pub = clock_node.create_publisher(Clock, '/clock', rclpy.qos.qos_profile_clock)
    ticks = []
    node.create_timer(0.5, lambda: ticks.append(node.get_clock().now().nanoseconds))
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    executor.add_node(clock_node)
    for i in range(1, 21):  # 2 s of sim time in 0.1 s steps, as fast as we can
        t = rclpy.time.Time(seconds=0.1 * i)
        pub.publish(Clock(clock=t.to_msg()))
        spin_until(node, lambda: False, timeout=0.01, executor=executor)
    spin_until(node, lambda: len(ticks) >= 4, timeout=2, executor=executor)
    assert [round(t / 1e9, 1) for t in ticks] == [0.5, 1.0, 1.5, 2.0]
    executor.shutdown()


def test_in_process_delivery_skips_serialisation(rclpy_ctx, monkeypatch):
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.sensor_msgs.msg import Image

    calls = []
    real = typesupport.serialize
    monkeypatch.setattr('mindgrasp_ros.runtime.publisher.serialize',
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    a, b = rclpy.node.Node('producer'), rclpy.node.Node('consumer')
    got = []
    b.create_subscription(Image, '/camera/color/image_raw', got.append, 5)
    pub = a.create_publisher(Image, '/camera/color/image_raw', 5)
    msg = Image(height=480, width=640, encoding='rgb8', step=1920,
                data=np.zeros(640 * 480 * 3, np.uint8))
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(b)
    pub.publish(msg)
    assert spin_until(b, lambda: bool(got), timeout=5, executor=executor)
    assert got[0] is msg and calls == []  # same object, never serialised (no remote reader)
    executor.shutdown()


def test_a_polled_subscription_is_read_by_its_owner_not_by_the_executor(rclpy_ctx):
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    a, b = rclpy.node.Node('writer'), rclpy.node.Node('poller')
    calls = []
    sub = b.create_subscription(String, '/polled', calls.append, 10, raw=True, polled=True)
    pub = a.create_publisher(String, '/polled', 10)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(b)
    for i in range(3):
        pub.publish(String(data=f'm{i}'))
    for _ in range(5):
        executor.spin_once(timeout_sec=0.05)
    assert calls == []  # the executor never takes it
    got = [typesupport.deserialize(data, 'std_msgs/msg/String').data for data, _ in sub.take()]
    assert got == ['m0', 'm1', 'm2'] and sub.take() == []
    executor.shutdown()


def test_malformed_sample_is_dropped_with_a_warning(rclpy_ctx, capfd):
    rclpy = rclpy_ctx
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    a, b = rclpy.node.Node('bad_writer'), rclpy.node.Node('reader')
    got = []
    sub = b.create_subscription(String, '/x', lambda m: got.append(m.data), 10)
    raw = a.create_publisher(String, '/x', 10, raw=True)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(b)
    raw.publish(b'\x00\x01\x00\x00\xff\xff\xff\x7f')  # string length 2**31: malformed
    raw.publish(typesupport.serialize(String(data='fine')))
    assert spin_until(b, lambda: got == ['fine'], timeout=5, executor=executor)
    assert sub.malformed_count == 1
    assert 'Dropped a malformed std_msgs/msg/String' in capfd.readouterr().err
    with pytest.raises(typesupport.MessageTypeError, match='carries std_msgs/msg/String'):
        a.create_publisher(String, '/y', 1).publish(rclpy.parameter.Parameter('x', value=1)
                                                      .get_parameter_value())
    executor.shutdown()


def test_lockstep_is_deterministic_and_serves_services():
    import random

    from mindgrasp_ros.interfaces.std_msgs.msg import Float64
    from mindgrasp_ros.interfaces.std_srvs.srv import Trigger

    from mindgrasp_ros import rclpy
    from mindgrasp_ros.graph.lockstep import LockstepRunner

    class Noise(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('noise', **kwargs)
            self.rng = random.Random(self.declare_parameter('seed', 0).value)
            pub = self.create_publisher(Float64, 'x', 10)
            self.create_timer(0.01, lambda: pub.publish(Float64(data=self.rng.random())))
            self.create_service(Trigger, 'reset', self.reset)

        def reset(self, _req, res):
            self.rng.seed(0)
            res.success = True
            return res

    class Log(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('log', **kwargs)
            self.values: list[tuple[int, float]] = []
            self.create_subscription(Float64, 'x', lambda m: self.values.append(
                (self.get_clock().now().nanoseconds, m.data)), 10)
            self.reset = self.create_client(Trigger, 'reset')

    runs = []
    for _ in range(2):
        with LockstepRunner() as runner:
            runner.add(Noise, ros_args=['-p', 'seed:=7'])
            log = runner.add(Log)
            for _ in range(50):
                runner.step(0.005)
            future = log.reset.call_async(Trigger.Request())
            runner.step(0.0)
            assert future.result().success
            runs.append(list(log.values))
    assert len(runs[0]) == 25 and runs[0] == runs[1]
    assert runs[0][0][0] == 10_000_000  # first tick at t = 10 ms of sim time


def test_multithreaded_executor_respects_callback_groups(rclpy_ctx):
    import threading
    import time

    rclpy = rclpy_ctx
    node = rclpy.node.Node('mt')
    active = {'n': 0, 'max_me': 0, 'max_re': 0}
    lock = threading.Lock()

    def work(key: str) -> None:
        with lock:
            active['n'] += 1
            active[key] = max(active[key], active['n'])
        time.sleep(0.05)
        with lock:
            active['n'] -= 1

    me = rclpy.callback_groups.MutuallyExclusiveCallbackGroup()
    for _ in range(3):
        node.create_timer(0.01, lambda: work('max_me'), callback_group=me)
    executor = rclpy.executors.MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    end = time.monotonic() + 0.6
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    assert active['max_me'] == 1  # never two callbacks of one exclusive group at once
    re = rclpy.callback_groups.ReentrantCallbackGroup()
    for _ in range(3):
        node.create_timer(0.01, lambda: work('max_re'), callback_group=re)
    end = time.monotonic() + 0.6
    while time.monotonic() < end:
        executor.spin_once(timeout_sec=0.05)
    executor.shutdown()
    assert active['max_re'] >= 2  # a reentrant group runs callbacks in parallel


def test_node_specific_remapping_and_log_level():
    from mindgrasp_ros import rclpy

    rclpy.init(args=['prog', '--ros-args', '-r', 'a:chatter:=/only_a', '-r', 'b:__ns:=/nsb',
                     '--log-level', 'a:=warn'])
    try:
        a = rclpy.node.Node('a')
        b = rclpy.node.Node('b')
        assert a.resolve_topic_name('chatter') == '/only_a'
        assert b.resolve_topic_name('chatter') == '/nsb/chatter'
        assert b.get_namespace() == '/nsb'
        assert a.get_logger().get_effective_level() == rclpy.logging.LoggingSeverity.WARN
        assert not a.get_logger().info('hidden')
    finally:
        rclpy.shutdown()


def test_lost_messages_are_counted(rclpy_ctx):
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    node = rclpy_ctx.node.Node('lossy')
    got = []
    sub = node.create_subscription(String, '/burst', lambda m: got.append(m.data), 5)
    pub = node.create_publisher(String, '/burst', 50)
    for i in range(20):
        pub.publish(String(data=str(i)))
    spin_until(node, lambda: len(got) >= 5, timeout=5)
    assert got == ['15', '16', '17', '18', '19']  # KEEP_LAST 5 keeps the newest
    assert sub.messages_lost == 15


def test_spin_once_waits_for_its_timeout_when_idle(rclpy_ctx):
    """rclpy.spin_once(node) adds and removes the node each call; that must not wake it."""
    import time

    node = rclpy_ctx.node.Node('idle')
    node.create_timer(5.0, lambda: None)
    start, calls = time.monotonic(), 0
    while time.monotonic() - start < 1.0:
        rclpy_ctx.spin_once(node, timeout_sec=0.1)
        calls += 1
    assert calls <= 15  # ~10 at 0.1 s each; a busy loop makes thousands


def test_a_ctrl_c_during_a_graph_query_is_not_lost(rclpy_ctx):
    """cyclonedds' C layer calls Python per sample during a graph read and turns what it raises
    into a plain error: a Ctrl-C arriving then must still reach the node's loop."""
    import os
    import signal

    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros.runtime.dds.discovery import _endpoint_without_type_id

    node = rclpy_ctx.node.Node('graph_interrupt')
    node.create_publisher(String, '/graph_interrupt', 10)
    assert spin_until(node, lambda: '/graph_interrupt' in dict(node.get_topic_names_and_types()),
                      timeout=60)
    graph = node.context.graph

    def interrupted(*args):
        os.kill(os.getpid(), signal.SIGINT)            # Ctrl-C while C reads an endpoint
        return _endpoint_without_type_id(*args)

    graph._pub_reader._constructor = interrupted
    node.create_publisher(String, '/graph_interrupt_2', 10)   # new: the next read decodes it
    deadline = time.monotonic() + 60
    with pytest.raises(KeyboardInterrupt):
        while time.monotonic() < deadline:
            node.get_topic_names_and_types()
            time.sleep(0.05)
    node.destroy_node()


_TAKE_INTERRUPTED = '''
import os, signal, sys, time
import cyclonedds.internal as ci
from mindgrasp_ros import rclpy
from mindgrasp_ros.interfaces.std_msgs.msg import String

rclpy.init()
node = rclpy.create_node('take_interrupt')
got = []
node.create_subscription(String, '/take_interrupt', got.append, 10)
deadline = time.monotonic() + 120
while not got and time.monotonic() < deadline:
    rclpy.spin_once(node, timeout_sec=0.1)
print('received', len(got), flush=True)
original = ci.SampleInfo.__init__

def interrupted(self, *args, **kwargs):      # Ctrl-C while C builds a sample's info
    ci.SampleInfo.__init__ = original
    os.kill(os.getpid(), signal.SIGINT)
    original(self, *args, **kwargs)

ci.SampleInfo.__init__ = interrupted
try:
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.1)
except KeyboardInterrupt:
    print('KeyboardInterrupt', flush=True)
    sys.exit(0)
sys.exit(3)
'''


def test_a_ctrl_c_during_a_take_is_a_keyboard_interrupt(rclpy_ctx):
    """cyclonedds' take builds each sample's info in Python from C: a Ctrl-C landing there made
    ``ddspy_take`` crash the process (an experiment stopped with Ctrl-C lost its report). It
    must reach the program as a KeyboardInterrupt. In a child process: a crash must not take the
    test runner with it; the publisher is here, as take only runs for another process's data."""
    import subprocess
    import sys

    from mindgrasp_ros.interfaces.std_msgs.msg import String

    node = rclpy_ctx.node.Node('take_interrupt_publisher')
    pub = node.create_publisher(String, '/take_interrupt', 10)
    child = subprocess.Popen([sys.executable, '-c', _TAKE_INTERRUPTED], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 180
    while child.poll() is None and time.monotonic() < deadline:
        pub.publish(String(data='x'))
        time.sleep(0.05)
    if child.poll() is None:
        child.kill()
    out, err = child.communicate(timeout=60)
    node.destroy_node()
    assert child.returncode == 0 and 'KeyboardInterrupt' in out, \
        (child.returncode, out, err[-2000:])


def test_generated_init_builds_what_the_generic_one_builds():
    """Every message class's written-out __init__ against Message.__init__: defaults, every
    field given by name (random content), positional fields and an unknown name."""
    rng = np.random.default_rng(11)
    store = typesupport.typestore()
    names = [n for n in store.fielddefs if '/msg/' in n]
    assert len(names) > 100
    for typename in names:
        cls = typesupport.get_message_class(typename)
        assert cls.__init__ is not typesupport.Message.__init__, typename
        generic = object.__new__(cls)
        typesupport.Message.__init__(generic)
        assert cls() == generic, typename
        filled = _random_message(typename, rng)
        given = {f: getattr(filled, f) for f in cls._fields}
        generic = object.__new__(cls)
        typesupport.Message.__init__(generic, **given)
        assert cls(**given) == generic == filled, typename
        assert cls(*given.values()) == filled, typename
        with pytest.raises(TypeError, match='has no field'):
            cls(no_such_field=1)
