"""Cyclone DDS plumbing, the way rmw_cyclonedds_cpp does it.

* One DDS participant per context (process); participant USER_DATA ``enclave=/;``.
* Topic names ``rt/<name>`` (services ``rq/<name>Request`` / ``rr/<name>Reply``), type names
  ``pkg::msg::dds_::Name_``; endpoint USER_DATA ``typehash=RIHS01_...;``.
* Samples are plain CDR (XCDR1). We register an IdlStruct generated from the ROS definition (so
  Cyclone announces correct XTypes type information and peers can match) but write and take raw
  bytes produced by the numpy CDR code in :mod:`mindgrasp_ros.typesupport`; cyclonedds-python's own
  serialiser is ~50x slower for images. ``ddspy_write``/``ddspy_take`` are private API of
  cyclonedds 11.0.1 (pinned in constraints.txt, covered by the transport tests).
* Discovery: ``ROS_DOMAIN_ID`` and ``ROS_AUTOMATIC_DISCOVERY_RANGE`` (LOCALHOST by default here,
  SUBNET, OFF or SYSTEM_DEFAULT), ``ROS_STATIC_PEERS``, ``CYCLONEDDS_URI`` taken as is when set.
"""

from __future__ import annotations

import functools
import os
import threading
from collections.abc import Callable
from typing import Any

from cyclonedds import idl
from cyclonedds._clayer import ddspy_take, ddspy_write
from cyclonedds.core import InstanceState, Listener, Policy, Qos, SampleState, ViewState
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter, Publisher
from cyclonedds.sub import DataReader, Subscriber
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from rosbags.typesys.base import Nodetype

from mindgrasp_ros.errors import RosError
from mindgrasp_ros.runtime.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from mindgrasp_ros.runtime.signal_guard import DDS_CALL
from mindgrasp_ros.typesupport import rihs01, typestore

__all__ = ['DdsParticipant', 'dds_type_name', 'ros_type_name_from_dds']

_ANY_STATE = SampleState.Any | ViewState.Any | InstanceState.Any
_MAX_AUTO_PARTICIPANT_INDEX = 100
# Best-effort 640x480 images arrive as ~640 UDP fragments each: the kernel's default receive
# buffer (rmem_default, ~208 kB) overflows and frames are lost. Ask for 4 MB (capped by
# net.core.rmem_max; 'default' minimum, so a smaller cap is not an error).
_SOCKET_BUFFERS = ('<Internal><SocketReceiveBufferSize min="default" max="4MB"/>'
                   '</Internal>')


class DdsError(RosError):
    """A DDS entity could not be created or used."""


# --------------------------------------------------------------------------- names

def dds_type_name(ros_type: str) -> str:
    """``sensor_msgs/msg/JointState`` -> ``sensor_msgs::msg::dds_::JointState_``."""
    package, kind, name = ros_type.split('/')
    return f'{package}::{kind}::dds_::{name}_'


def ros_type_name_from_dds(dds_name: str) -> str | None:
    """Inverse of :func:`dds_type_name`; None for non-ROS types."""
    parts = dds_name.split('::')
    if len(parts) != 4 or parts[2] != 'dds_' or not parts[3].endswith('_'):
        return None
    return f'{parts[0]}/{parts[1]}/{parts[3][:-1]}'


def ros_topic_name_from_dds(dds_topic: str) -> tuple[str, str] | None:
    """DDS topic -> (ROS name, kind) with kind 'topic', 'request' or 'reply'; None if not ROS."""
    if dds_topic.startswith('rt/'):
        return '/' + dds_topic[3:], 'topic'
    if dds_topic.startswith('rq/') and dds_topic.endswith('Request'):
        return '/' + dds_topic[3:-7], 'request'
    if dds_topic.startswith('rr/') and dds_topic.endswith('Reply'):
        return '/' + dds_topic[3:-5], 'reply'
    return None


# --------------------------------------------------------------------------- IDL types

_IDL_BASE = {
    'bool': bool, 'byte': t.uint8, 'char': t.uint8, 'int8': t.int8, 'uint8': t.uint8,
    'int16': t.int16, 'uint16': t.uint16, 'int32': t.int32, 'uint32': t.uint32,
    'int64': t.int64, 'uint64': t.uint64, 'float32': t.float32, 'float64': t.float64,
}
_idl_lock = threading.RLock()


def _idl_field(desc: tuple) -> Any:
    kind, detail = desc
    if kind == Nodetype.BASE:
        base, bound = detail
        if base == 'string':
            return t.bounded_str[bound] if bound else str
        return _IDL_BASE[base]
    if kind == Nodetype.NAME:
        return idl_struct(detail)
    sub, count = detail
    inner = _idl_field(sub)
    if kind == Nodetype.ARRAY:
        return t.array[inner, count]
    return t.sequence[inner, count] if count else t.sequence[inner]


@functools.cache
def _idl_struct_cached(ros_type: str) -> type:
    fields: dict[str, Any] = {}
    for name, desc in typestore().fielddefs[ros_type][1]:
        fields[name] = _idl_field(desc)
    if not fields:
        fields['structure_needs_at_least_one_member'] = t.uint8
    # final extensibility (the default): plain XCDR1 like ROS 2's generated types
    return idl.make_idl_struct(ros_type.replace('/', '_'), dds_type_name(ros_type), fields)


def idl_struct(ros_type: str) -> type:
    """A cyclonedds IdlStruct with the DDS type name and layout of a ROS type."""
    with _idl_lock:
        return _idl_struct_cached(ros_type)


@functools.cache
def _service_wire_type(ros_type: str, role: str) -> type:
    """Request/reply wire type: rmw_cyclonedds prefixes ``uint64 guid; int64 seq``."""
    base = idl_struct(ros_type)
    fields = {'guid_': t.uint64, 'seq_': t.int64}
    fields.update({f'payload_{k}': v for k, v in base.__annotations__.items()})
    return idl.make_idl_struct(f'{ros_type.replace("/", "_")}_{role}', dds_type_name(ros_type),
                               fields)


# --------------------------------------------------------------------------- QoS

def to_dds_qos(qos: QoSProfile, user_data: bytes | None = None, *,
               ignore_local: bool = False) -> Qos:
    """Cyclone QoS of a ROS QoS profile (as rmw_cyclonedds maps it)."""
    policies: list[Any] = []
    if qos.history == HistoryPolicy.KEEP_ALL:
        policies.append(Policy.History.KeepAll)
    else:
        policies.append(Policy.History.KeepLast(max(1, int(qos.depth))))
    if qos.reliability == ReliabilityPolicy.BEST_EFFORT:
        policies.append(Policy.Reliability.BestEffort)
    else:
        policies.append(Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)))
    if qos.durability == DurabilityPolicy.TRANSIENT_LOCAL:
        policies.append(Policy.Durability.TransientLocal)
        depth = max(1, int(qos.depth)) if qos.history != HistoryPolicy.KEEP_ALL else 1000
        policies.append(Policy.DurabilityService(
            cleanup_delay=0, history=Policy.History.KeepLast(depth), max_samples=-1,
            max_instances=-1, max_samples_per_instance=-1))
    else:
        policies.append(Policy.Durability.Volatile)
    if qos.deadline.nanoseconds > 0:
        policies.append(Policy.Deadline(qos.deadline.nanoseconds))
    if qos.lifespan.nanoseconds > 0:
        policies.append(Policy.Lifespan(qos.lifespan.nanoseconds))
    lease = qos.liveliness_lease_duration.nanoseconds
    lease_ns = lease if lease > 0 else duration(infinite=True)
    if qos.liveliness == LivelinessPolicy.MANUAL_BY_TOPIC:
        policies.append(Policy.Liveliness.ManualByTopic(lease_ns))
    else:
        policies.append(Policy.Liveliness.Automatic(lease_ns))
    policies.append(Policy.DataRepresentation(use_cdrv0_representation=True))
    if user_data is not None:
        policies.append(Policy.Userdata(user_data))
    if ignore_local:
        policies.append(Policy.IgnoreLocal.Participant)
    return Qos(*policies)


# --------------------------------------------------------------------------- configuration

def _discovery_config(domain_id: int) -> str | None:
    if os.environ.get('CYCLONEDDS_URI'):
        return None  # the user's own configuration wins, as with rmw_cyclonedds
    scope = os.environ.get('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST').strip().upper()
    peers = [p.strip() for p in os.environ.get('ROS_STATIC_PEERS', '').replace(',', ';').split(';')
             if p.strip()]
    if scope in ('', 'LOCALHOST'):
        peer_xml = ''.join(f'<Peer address="{p}"/>' for p in ['localhost', *peers])
        return (
            '<CycloneDDS><Domain id="any"><General><Interfaces>'
            '<NetworkInterface address="127.0.0.1"/></Interfaces>'
            '<AllowMulticast>false</AllowMulticast></General>'
            f'{_SOCKET_BUFFERS}'
            '<Discovery><ParticipantIndex>auto</ParticipantIndex>'
            f'<MaxAutoParticipantIndex>{_MAX_AUTO_PARTICIPANT_INDEX}</MaxAutoParticipantIndex>'
            f'<Peers>{peer_xml}</Peers></Discovery></Domain></CycloneDDS>')
    if scope == 'OFF':
        return ('<CycloneDDS><Domain id="any"><General><Interfaces>'
                '<NetworkInterface address="127.0.0.1"/></Interfaces>'
                '<AllowMulticast>false</AllowMulticast></General>'
                '<Discovery><ParticipantIndex>none</ParticipantIndex></Discovery>'
                '</Domain></CycloneDDS>')
    if scope in ('SUBNET', 'SYSTEM_DEFAULT'):
        if not peers:
            return f'<CycloneDDS><Domain id="any">{_SOCKET_BUFFERS}</Domain></CycloneDDS>'
        peer_xml = ''.join(f'<Peer address="{p}"/>' for p in peers)
        return (f'<CycloneDDS><Domain id="any">{_SOCKET_BUFFERS}<Discovery><Peers>{peer_xml}'
                '</Peers></Discovery></Domain></CycloneDDS>')
    msg = (f'ROS_AUTOMATIC_DISCOVERY_RANGE={scope!r} is not valid; use LOCALHOST, SUBNET, OFF '
           'or SYSTEM_DEFAULT.')
    raise DdsError(msg)


def domain_id_from_env() -> int:
    """``ROS_DOMAIN_ID`` (0 when unset), validated."""
    raw = os.environ.get('ROS_DOMAIN_ID', '').strip()
    if not raw:
        return 0
    try:
        value = int(raw)
    except ValueError:
        value = -1
    if not 0 <= value <= 232:
        msg = f'ROS_DOMAIN_ID={raw!r} is not valid; use an integer from 0 to 232.'
        raise DdsError(msg)
    return value


# --------------------------------------------------------------------------- participant

class DdsReader:
    """A raw-CDR DataReader (executors attach their own ReadConditions to it).

    ``lost`` counts samples DDS reports lost or rejected (a full history or resource limit);
    the listener fires only on such events, so the data path stays free of Python callbacks.
    """

    def __init__(self) -> None:
        self.reader: DataReader | None = None
        self.lost = 0
        self.listener = Listener(on_sample_lost=self._on_lost, on_sample_rejected=self._on_lost)

    def _on_lost(self, _reader: object, status: Any) -> None:
        self.lost += max(0, int(status.total_count_change))

    def take(self, n: int = 64) -> list[tuple[bytes, Any]]:
        """Up to n valid samples as (CDR bytes incl. header, SampleInfo)."""
        with DDS_CALL:      # it builds each SampleInfo in Python, from C
            ret = ddspy_take(self.reader._ref, _ANY_STATE, n)
        if isinstance(ret, int):
            msg = f'DDS take failed with code {ret}.'
            raise DdsError(msg)
        return [(data, info) for data, info in ret if info.valid_data]

    @property
    def guid(self) -> bytes:
        return self.reader.guid.bytes

    def matched_count(self) -> int:
        return _matched(self.reader.get_matched_publications)

    def matched_user_data(self, key: str) -> set[str]:
        """The values of ``key`` in the USER_DATA of the matched writers."""
        return _user_data_values(self.reader.get_matched_publications,
                                 self.reader.get_matched_publication_data, key)

    def writer_participant(self, publication_handle: int) -> Any | None:
        """Participant GUID of a matched writer (a SampleInfo's ``publication_handle``), or None
        once that writer is gone."""
        data = self.reader.get_matched_publication_data(publication_handle)
        return None if data is None else data.participant_key

    def writers_of(self, participant: Any) -> int:
        """How many matched writers belong to ``participant``."""
        return _count_in(self.reader.get_matched_publications,
                         self.reader.get_matched_publication_data, participant)


class DdsWriter:
    """A raw-CDR DataWriter."""

    def __init__(self, writer: DataWriter) -> None:
        self.writer = writer
        self._ref = writer._ref

    def write(self, data: bytes) -> None:
        """Write CDR bytes (with the 4-byte encapsulation header)."""
        pad = (-len(data)) % 4
        if pad:
            data = data + b'\0' * pad
        ret = ddspy_write(self._ref, data)
        if ret < 0:
            msg = f'DDS write failed with code {ret}.'
            raise DdsError(msg)

    @property
    def guid(self) -> bytes:
        return self.writer.guid.bytes

    def matched_count(self) -> int:
        return _matched(self.writer.get_matched_subscriptions)

    def matched_user_data(self, key: str) -> set[str]:
        """The values of ``key`` in the USER_DATA of the matched readers."""
        return _user_data_values(self.writer.get_matched_subscriptions,
                                 self.writer.get_matched_subscription_data, key)

    def readers_of(self, participant: Any) -> int:
        """How many matched readers belong to ``participant`` (a participant GUID)."""
        return _count_in(self.writer.get_matched_subscriptions,
                         self.writer.get_matched_subscription_data, participant)


def user_data(qos: Any) -> dict[str, str]:
    """The ``key=value;`` pairs of an endpoint QoS's USER_DATA (rmw's ``typehash=``,
    ``clientid=``, ``serviceid=``)."""
    pairs: dict[str, str] = {}
    for policy in qos or ():
        if getattr(policy, '__scope__', '') == 'Userdata':
            for part in bytes(policy.data).decode(errors='replace').split(';'):
                name, sep, value = part.partition('=')
                if sep:
                    pairs[name] = value
    return pairs


def _user_data_values(handles: Callable[[], list[int]], data: Callable[[int], Any],
                      key: str) -> set[str]:
    """Values of ``key`` in the USER_DATA of matched endpoints (those that unmatch meanwhile
    give None and are skipped)."""
    values = set()
    for handle in handles():
        endpoint = data(handle)
        value = user_data(endpoint.qos).get(key) if endpoint is not None else None
        if value is not None:
            values.add(value)
    return values


def _count_in(handles: Callable[[], list[int]], data: Callable[[int], Any],
              participant: Any) -> int:
    """Matched endpoints of one participant (handles of endpoints that unmatch meanwhile give
    None and are not counted)."""
    for _ in range(3):
        try:
            found = handles()
            break
        except IndexError:      # an endpoint matched while listing (see _matched)
            continue
    else:
        return 0
    return sum(1 for h in found if (d := data(h)) is not None and d.participant_key == participant)


def _matched(handles: Callable[[], list[int]]) -> int:
    """How many endpoints are matched. cyclonedds-python sizes the handle list from a first count
    and then fills it; an endpoint that matches between the two calls makes it index past the list
    (IndexError), e.g. a recorder or live view subscribing while a node publishes. Ask again; while
    endpoints keep matching, say 'at least one' (the caller then writes, which is always safe)."""
    for _ in range(3):
        try:
            return len(handles())
        except IndexError:
            continue
    return 1


class DdsParticipant:
    """The process's DDS participant with its publisher, subscriber and topics."""

    def __init__(self, domain_id: int | None = None) -> None:
        self.domain_id = domain_id_from_env() if domain_id is None else domain_id
        config = _discovery_config(self.domain_id)
        self._domain = Domain(self.domain_id, config) if config else None
        self.participant = DomainParticipant(
            self.domain_id, qos=Qos(Policy.Userdata(b'enclave=/;')))
        self.publisher = Publisher(self.participant)
        self.subscriber = Subscriber(self.participant)
        self._topics: dict[str, Topic] = {}
        self._lock = threading.RLock()

    @property
    def guid(self) -> bytes:
        return self.participant.guid.bytes

    def _topic(self, dds_topic: str, data_type: type) -> Topic:
        # One Topic per name per participant: Cyclone refuses a second one with other QoS,
        # and a topic has one type.
        with self._lock:
            topic = self._topics.get(dds_topic)
            if topic is None:
                topic = Topic(self.participant, dds_topic, data_type)
                self._topics[dds_topic] = topic
            elif topic.data_type is not data_type:
                have = ros_type_name_from_dds(topic.data_type.__idl_typename__.replace('.', '::'))
                want = ros_type_name_from_dds(data_type.__idl_typename__.replace('.', '::'))
                msg = (f"Topic '{dds_topic[2:] if dds_topic[:3] in ('rt/',) else dds_topic}' "
                       f'is already used with type {have} in this process; it cannot also carry '
                       f'{want}. Use one type per topic (or another topic name).')
                raise DdsError(msg)
            return topic

    def create_writer(self, dds_topic: str, ros_type: str, qos: QoSProfile, *,
                      service_role: str | None = None, type_hash: str | None = None,
                      extra_user_data: str = '') -> DdsWriter:
        """``extra_user_data``: ``key=value;`` pairs before the type hash, as rmw_cyclonedds
        puts a client's ``clientid=`` or a service's ``serviceid=`` there."""
        data_type = (_service_wire_type(ros_type, service_role) if service_role
                     else idl_struct(ros_type))
        user_data = f'{extra_user_data}typehash={type_hash or rihs01(ros_type)};'.encode()
        with self._lock:
            writer = DataWriter(self.publisher, self._topic(dds_topic, data_type),
                                qos=to_dds_qos(qos, user_data))
        return DdsWriter(writer)

    def create_reader(self, dds_topic: str, ros_type: str, qos: QoSProfile, *,
                      service_role: str | None = None, ignore_local: bool = False,
                      type_hash: str | None = None, extra_user_data: str = '') -> DdsReader:
        data_type = (_service_wire_type(ros_type, service_role) if service_role
                     else idl_struct(ros_type))
        user_data = f'{extra_user_data}typehash={type_hash or rihs01(ros_type)};'.encode()
        with self._lock:
            wrapper = DdsReader()
            wrapper.reader = DataReader(
                self.subscriber, self._topic(dds_topic, data_type),
                qos=to_dds_qos(qos, user_data, ignore_local=ignore_local),
                listener=wrapper.listener)
        return wrapper

    def delete_reader(self, reader: DdsReader) -> None:
        with self._lock:
            reader.reader.__del__()  # explicit, not left to the GC

    def delete_writer(self, writer: DdsWriter) -> None:
        with self._lock:
            writer.writer.__del__()

    def close(self) -> None:
        with self._lock:
            self.participant.__del__()
            self._topics.clear()
            # explicit too: a Domain left to the GC (e.g. kept by a reference cycle) makes the
            # next rclpy.init() in this process fail with PRECONDITION_NOT_MET
            if self._domain is not None:
                self._domain.__del__()
                self._domain = None
