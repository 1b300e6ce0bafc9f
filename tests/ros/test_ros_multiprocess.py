"""mindgrasp_ros across processes: pub/sub QoS, late joiners, services, parameters, remapping,
graph introspection, and a peer that does not use our code (plain cyclonedds)."""

import time
from pathlib import Path

import pytest

from mindgrasp_testing import spin_until

pytestmark = pytest.mark.slow

PEER = str(Path(__file__).with_name('ros_peer.py'))


def _listener(rclpy, topic, reliable=True, transient=False, depth=10):
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    node = rclpy.node.Node('test_listener')
    got: list[str] = []
    qos = rclpy.qos.QoSProfile(
        depth=depth,
        reliability=rclpy.qos.ReliabilityPolicy.RELIABLE if reliable
        else rclpy.qos.ReliabilityPolicy.BEST_EFFORT,
        durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL if transient
        else rclpy.qos.DurabilityPolicy.VOLATILE)
    node.create_subscription(String, topic, lambda m: got.append(m.data), qos)
    return node, got


@pytest.mark.parametrize(('writer_reliable', 'reader_reliable', 'delivers'), [
    (True, True, True),
    (True, False, True),   # best-effort reader matches a reliable writer
    (False, False, True),
    (False, True, False),  # a reliable reader does not match a best-effort writer
])
def test_pubsub_qos_matching(rclpy_ctx, spawn_node, writer_reliable, reader_reliable, delivers):
    talker = spawn_node(PEER, 'talker', '--ros-args', '-p',
                        f'reliable:={str(writer_reliable).lower()}')
    node, got = _listener(rclpy_ctx, '/chatter', reliable=reader_reliable)
    if delivers:
        assert spin_until(node, lambda: len(got) >= 10, timeout=60), talker.output()
        numbers = [int(s.split()[1]) for s in got]
        assert numbers == sorted(numbers)
        if writer_reliable and reader_reliable:
            assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))
    else:
        spin_until(node, lambda: bool(got), timeout=3)
        assert got == []


def test_transient_local_late_joiner(rclpy_ctx, spawn_node):
    peer = spawn_node(PEER, 'latched', '--ros-args', '-p', 'transient_local:=true',
                      '-p', 'depth:=2')
    assert peer.wait_for_output('ready')
    time.sleep(0.5)  # the messages were published before we exist
    node, got = _listener(rclpy_ctx, '/latched', transient=True)
    assert spin_until(node, lambda: len(got) >= 2, timeout=60), peer.output()
    spin_until(node, lambda: False, timeout=0.5)
    assert got == ['latched 1', 'latched 2']  # depth 2 keeps the last two


def test_remapping_and_node_name_from_command_line(rclpy_ctx, spawn_node):
    spawn_node(PEER, 'talker', '--ros-args', '-r', 'chatter:=/remapped/chat',
               '-r', '__node:=renamed', '-r', '__ns:=/lab')
    node, got = _listener(rclpy_ctx, '/remapped/chat')
    assert spin_until(node, lambda: len(got) >= 3, timeout=60)
    assert spin_until(node, lambda: ('renamed', '/lab') in node.get_node_names_and_namespaces(),
                      timeout=60)
    infos = node.get_publishers_info_by_topic('/remapped/chat')
    assert [(i.node_name, i.node_namespace) for i in infos] == [('renamed', '/lab')]
    assert infos[0].topic_type == 'std_msgs/msg/String'
    assert infos[0].topic_type_hash.startswith('RIHS01_df668c74')


def test_services_and_parameters_across_processes(rclpy_ctx, spawn_node, tmp_path):
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import Parameter, ParameterValue
    from mindgrasp_ros.interfaces.rcl_interfaces.srv import GetParameters, SetParameters
    from mindgrasp_ros.interfaces.std_srvs.srv import SetBool

    params = tmp_path / 'peer.yaml'
    params.write_text(
        '/**:\n  ros__parameters:\n    name: from_wildcard\n'
        'peer_params:\n  ros__parameters:\n    gain: 2.5\n    nested: {level: 3}\n'
        '    channels: [C3, Cz, C4]\n')
    spawn_node(PEER, 'params', '--ros-args', '--params-file', str(params), '-p', 'gain:=4.0')
    rclpy = rclpy_ctx
    node = rclpy.node.Node('test_client')
    get = node.create_client(GetParameters, '/peer_params/get_parameters')
    assert get.wait_for_service(timeout_sec=60)
    future = get.call_async(GetParameters.Request(names=['gain', 'name', 'nested.level',
                                                         'channels']))
    rclpy.spin_until_future_complete(node, future, timeout_sec=60)
    values = future.result().values
    assert values[0].double_value == 4.0  # -p wins over the file
    assert values[1].string_value == 'from_wildcard'
    assert values[2].integer_value == 3
    assert list(values[3].string_array_value) == ['C3', 'Cz', 'C4']

    set_ = node.create_client(SetParameters, '/peer_params/set_parameters')
    assert set_.wait_for_service(timeout_sec=60)
    future = set_.call_async(SetParameters.Request(parameters=[
        Parameter(name='gain', value=ParameterValue(type=3, double_value=7.0)),
        Parameter(name='gain', value=ParameterValue(type=4, string_value='oops'))]))
    rclpy.spin_until_future_complete(node, future, timeout_sec=60)
    ok, wrong_type = future.result().results
    assert ok.successful
    assert not wrong_type.successful and 'expected DOUBLE' in wrong_type.reason

    toggle = node.create_client(SetBool, '/toggle')
    assert toggle.wait_for_service(timeout_sec=60)
    # paired as rmw_cyclonedds pairs them: the server's request reader and reply writer say one
    # serviceid, and the client's endpoints say a clientid (so a real rclpy server waits for
    # this client's reply reader before it answers)
    servers = toggle._writer.matched_user_data('serviceid')
    assert len(servers) == 1 and servers == toggle._reader.matched_user_data('serviceid')
    future = toggle.call_async(SetBool.Request(data=True))
    rclpy.spin_until_future_complete(node, future, timeout_sec=60)
    assert future.result().message == 'on=True gain=7.0'


def test_a_reply_waits_for_the_callers_reply_reader(rclpy_ctx, spawn_node):
    """A caller whose reply reader the service has not discovered yet still gets its reply:
    the service waits for it (as rmw_cyclonedds does) instead of writing to no one. Here the
    reply reader is created only after the request has gone out."""
    from mindgrasp_ros.interfaces.std_srvs.srv import SetBool

    from mindgrasp_ros import using_real_rclpy
    from mindgrasp_ros.runtime.service import pack_service, service_topics, unpack_service
    from mindgrasp_ros.typesupport import deserialize, serialize

    if using_real_rclpy():
        pytest.skip('drives the DDS layer of the built-in client library')
    peer = spawn_node(PEER, 'params')
    node = rclpy_ctx.node.Node('late_reader_client')
    assert node.create_client(SetBool, '/toggle').wait_for_service(timeout_sec=60), peer.output()
    dds = node.context.dds
    req_topic, rep_topic = service_topics('/toggle')
    qos = rclpy_ctx.qos.QoSProfile(depth=10)
    writer = dds.create_writer(req_topic, 'std_srvs/srv/SetBool_Request', qos,
                               service_role='request')
    assert spin_until(node, lambda: writer.matched_count() > 0, timeout=60)
    writer.write(pack_service(99, 1, serialize(SetBool.Request(data=True),
                                                'std_srvs/srv/SetBool_Request')))
    time.sleep(0.5)   # the condition under test: no reply reader when the request arrives
    reader = dds.create_reader(rep_topic, 'std_srvs/srv/SetBool_Response', qos,
                               service_role='reply')
    replies = []

    def replied() -> bool:
        replies.extend(reader.take())
        return bool(replies)

    assert spin_until(node, replied, timeout=60), peer.output()
    guid, seq, payload = unpack_service(replies[0][0])
    assert (guid, seq) == (99, 1)
    assert deserialize(payload, 'std_srvs/srv/SetBool_Response').message.startswith('on=True')
    dds.delete_reader(reader)
    dds.delete_writer(writer)


def test_ros_discovery_info_lists_nodes_and_endpoints(rclpy_ctx, spawn_node):
    spawn_node(PEER, 'echo')
    node = rclpy_ctx.node.Node('observer')
    assert spin_until(node, lambda: 'peer_echo' in node.get_node_names(), timeout=60)
    assert 'observer' in node.get_node_names()
    graph = node.context.graph

    def complete() -> bool:
        ep = graph.node_endpoints('peer_echo', '/')
        return (('/echo', 'std_msgs/msg/String') in ep.get('publishers', [])
                and ('/chatter', 'std_msgs/msg/String') in ep.get('subscribers', [])
                and len(ep.get('services', [])) >= 6)

    assert spin_until(node, complete, timeout=60)
    endpoints = graph.node_endpoints('peer_echo', '/')
    assert ('/chatter', 'std_msgs/msg/String') in endpoints['subscribers']
    assert ('/rosout', 'rcl_interfaces/msg/Log') in endpoints['publishers']
    assert ('/peer_echo/get_parameters', 'rcl_interfaces/srv/GetParameters') in \
        endpoints['services']
    topics = dict(node.get_topic_names_and_types())
    assert topics['/chatter'] == ['std_msgs/msg/String']
    subs = node.get_subscriptions_info_by_topic('/chatter')
    assert subs[0].qos_profile.reliability == rclpy_ctx.qos.ReliabilityPolicy.RELIABLE
    assert subs[0].qos_profile.depth == 10


def test_plain_cyclonedds_peer_exchanges_messages(rclpy_ctx, spawn_node):
    """A peer that uses none of our code: cyclonedds-python with a hand-written IDL type named
    as rmw_cyclonedds names std_msgs/String, on the DDS topic rt/chatter."""
    from dataclasses import dataclass

    from cyclonedds.core import Policy, Qos
    from cyclonedds.domain import DomainParticipant
    from cyclonedds.idl import IdlStruct
    from cyclonedds.pub import DataWriter
    from cyclonedds.sub import DataReader
    from cyclonedds.topic import Topic

    @dataclass
    class String_(IdlStruct, typename='std_msgs::msg::dds_::String_'):  # noqa: N801
        data: str

    echo = spawn_node(PEER, 'echo')
    assert echo.wait_for_output('ready')
    dp = DomainParticipant(rclpy_ctx.get_default_context().domain_id)
    qos = Qos(Policy.Reliability.Reliable(0), Policy.History.KeepLast(10),
              Policy.DataRepresentation(use_cdrv0_representation=True))
    writer = DataWriter(dp, Topic(dp, 'rt/chatter', String_), qos=qos)
    reader = DataReader(dp, Topic(dp, 'rt/echo', String_), qos=qos)
    received: list[str] = []
    deadline = time.monotonic() + 20
    i = 0
    while time.monotonic() < deadline and len(received) < 3:
        i += 1
        writer.write(String_(data=f'plain dds {i}'))
        time.sleep(0.05)
        received += [s.data for s in reader.take(N=10)]
    assert received and received[0].startswith('plain dds'), echo.output()
