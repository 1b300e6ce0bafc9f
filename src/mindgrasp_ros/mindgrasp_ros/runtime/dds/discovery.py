"""Graph introspection for any ROS 2 graph on the domain.

Endpoints come from DDS discovery (the built-in DCPSPublication/DCPSSubscription topics); node
names and which node owns which endpoint come from ``ros_discovery_info`` (rmw_dds_common), which
every rmw_cyclonedds / rmw_fastrtps participant and ours publish. The same sources ``ros2 node
list`` and ``ros2 topic info -v`` use, so the answers agree with the ROS 2 tools.
"""

from __future__ import annotations

import math
import threading
import time
import uuid
from collections import defaultdict
from typing import Any

from cyclonedds.builtin import (
    BuiltinDataReader,
    BuiltinTopicDcpsPublication,
    BuiltinTopicDcpsSubscription,
)
from cyclonedds.builtin_types import DcpsEndpoint
from cyclonedds.core import InstanceState, Policy, Qos, ReadCondition, SampleState, ViewState
from cyclonedds.util import duration

from mindgrasp_ros.runtime.dds.participant import (
    DdsParticipant,
    ros_topic_name_from_dds,
    ros_type_name_from_dds,
    user_data,
)
from mindgrasp_ros.runtime.duration import Duration
from mindgrasp_ros.runtime.endpoint_info import TopicEndpointInfo
from mindgrasp_ros.runtime.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from mindgrasp_ros.runtime.signal_guard import DDS_CALL
from mindgrasp_ros.typesupport import deserialize

__all__ = ['GraphCache', 'TopicEndpointInfo']


def _qos_from_dds(qos: Any) -> QoSProfile:
    profile = QoSProfile(depth=0)
    for policy in qos:
        scope = getattr(policy, '__scope__', '')
        if scope == 'Reliability':
            profile.reliability = (ReliabilityPolicy.BEST_EFFORT
                                   if 'BestEffort' in type(policy).__name__
                                   or policy == Policy.Reliability.BestEffort
                                   else ReliabilityPolicy.RELIABLE)
        elif scope == 'Durability':
            profile.durability = (DurabilityPolicy.TRANSIENT_LOCAL
                                  if policy == Policy.Durability.TransientLocal
                                  else DurabilityPolicy.VOLATILE)
        elif scope == 'History':
            if policy == Policy.History.KeepAll:
                profile.history = HistoryPolicy.KEEP_ALL
            else:
                profile.history = HistoryPolicy.KEEP_LAST
                profile.depth = int(getattr(policy, 'depth', 0))
        elif scope == 'Deadline':
            profile.deadline = _duration(policy.deadline)
        elif scope == 'Lifespan':
            profile.lifespan = _duration(policy.lifespan)
        elif scope == 'Liveliness':
            profile.liveliness = (LivelinessPolicy.MANUAL_BY_TOPIC
                                  if 'ManualByTopic' in repr(policy)
                                  else LivelinessPolicy.AUTOMATIC)
            profile.liveliness_lease_duration = _duration(policy.lease_duration)
    return profile


def _endpoint_without_type_id(keybytes: bytes, participant_keybytes: bytes, handle: int,
                              topic_name: str | None, type_name: str | None, qos: Any,
                              sample_info: Any, _type_id: bytes | None = None) -> DcpsEndpoint:
    """cyclonedds' ``endpoint_constructor`` without decoding the XTypes type identifier.

    The graph never uses it, and cyclonedds' ``TypeIdentifier.deserialize`` of some endpoints'
    bytes looped for ever (a recorder listing topics hung on SIGINT; found with a faulthandler
    dump) or raised ("Callfunc endpoint constructor errored", failing the whole read).
    """
    endpoint = DcpsEndpoint(uuid.UUID(bytes=keybytes), uuid.UUID(bytes=participant_keybytes),
                            handle, topic_name, type_name, qos, None)
    endpoint.sample_info = sample_info
    return endpoint


#: most endpoints one graph query reads (a ROS graph of a few hundred nodes)
_MAX_ENDPOINTS = 8192
#: how long (s) Cyclone keeps a disposed endpoint's sample for a query to see
_PURGE_SEC = 10.0


def _duration(ns: int) -> Duration:
    return Duration(nanoseconds=0 if ns >= 2**62 else ns)


def _user_data_hash(qos: Any) -> str:
    return user_data(qos).get('typehash', '')


class GraphCache:
    """Endpoints and nodes of the domain, updated on every query."""

    def __init__(self, dds: DdsParticipant) -> None:
        self._dds = dds
        self._lock = threading.Lock()
        # The endpoints are *read*, not taken, and Cyclone purges disposed ones itself after
        # _PURGE_SEC. A query reads only what is new since the last one: reading every endpoint
        # (each decoded in Python) cost ~0.3 s with 120 endpoints on a loaded host, and a
        # recorder asking about each of its topics stalled for seconds and lost EEG. A query
        # more than _PURGE_SEC / 2 after the previous one reads every alive endpoint instead: a
        # disposal it did not see may have been purged meanwhile.
        purge = Qos(Policy.ReaderDataLifecycle(
            autopurge_nowriter_samples_delay=duration(seconds=_PURGE_SEC),
            autopurge_disposed_samples_delay=duration(seconds=_PURGE_SEC)))
        self._pub_reader = BuiltinDataReader(dds.participant, BuiltinTopicDcpsPublication,
                                             qos=purge)
        self._sub_reader = BuiltinDataReader(dds.participant, BuiltinTopicDcpsSubscription,
                                             qos=purge)
        readers = (self._pub_reader, self._sub_reader)
        for reader in readers:
            reader._constructor = _endpoint_without_type_id
        alive = ViewState.Any | SampleState.Any | InstanceState.Alive
        new = ViewState.Any | SampleState.NotRead | InstanceState.Any
        self._alive = {id(r): ReadCondition(r, alive) for r in readers}
        self._new = {id(r): ReadCondition(r, new) for r in readers}
        self._updated_at = -math.inf     # time.monotonic() of the last query
        self._info_reader = dds.create_reader(
            'ros_discovery_info', 'rmw_dds_common/msg/ParticipantEntitiesInfo',
            QoSProfile(history=HistoryPolicy.KEEP_ALL, durability=DurabilityPolicy.TRANSIENT_LOCAL))
        self._endpoints: dict[bytes, tuple[str, Any]] = {}  # gid -> (kind, DcpsEndpoint)
        #: participant gid -> [(namespace, name, reader gids, writer gids)]
        self._participants: dict[bytes, list[tuple[str, str, set[bytes], set[bytes]]]] = {}

    def close(self) -> None:
        try:
            self._dds.delete_reader(self._info_reader)
            self._pub_reader.__del__()
            self._sub_reader.__del__()
        except Exception:
            pass

    def _read(self, reader: BuiltinDataReader, condition: ReadCondition) -> list[Any]:
        with DDS_CALL:
            samples = reader.read(N=_MAX_ENDPOINTS, condition=condition)
        return [s for s in samples if s is not None]

    def _update(self) -> None:
        with self._lock:
            kinds = (('publisher', self._pub_reader), ('subscription', self._sub_reader))
            now = time.monotonic()
            if now - self._updated_at >= _PURGE_SEC / 2:
                self._endpoints = {s.key.bytes: (kind, s) for kind, reader in kinds
                                   for s in self._read(reader, self._alive[id(reader)])
                                   if s.topic_name}
            else:
                for kind, reader in kinds:
                    for s in self._read(reader, self._new[id(reader)]):
                        if s.sample_info.instance_state == InstanceState.Alive and s.topic_name:
                            self._endpoints[s.key.bytes] = (kind, s)
                        else:                   # disposed, or its participant left
                            self._endpoints.pop(s.key.bytes, None)
            self._updated_at = now
            for data, _info in self._info_reader.take(1024):
                try:
                    msg = deserialize(data, 'rmw_dds_common/msg/ParticipantEntitiesInfo')
                except Exception:
                    continue
                gid = bytes(msg.gid.data)[:16]
                self._participants[gid] = [
                    (n.node_namespace, n.node_name,
                     {bytes(g.data)[:16] for g in n.reader_gid_seq},
                     {bytes(g.data)[:16] for g in n.writer_gid_seq})
                    for n in msg.node_entities_info_seq]
            # forget participants whose endpoints are all gone
            live_participants = {ep.participant_key.bytes for _k, ep in self._endpoints.values()}
            for gid in list(self._participants):
                if gid not in live_participants:
                    del self._participants[gid]

    def _owner(self, gid: bytes, participant: bytes) -> tuple[str, str]:
        for ns, name, readers, writers in self._participants.get(participant, []):
            if gid in readers or gid in writers:
                return name, ns
        return '_NODE_NAME_UNKNOWN_', '_NODE_NAMESPACE_UNKNOWN_'

    # ------------------------------------------------------------------ queries
    def node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """Every node of every participant; two nodes of one name in two participants are
        listed twice, as rcl lists them (``ros2 node list`` shows both, with a warning)."""
        self._update()
        with self._lock:
            out = [(name, ns) for nodes in self._participants.values()
                   for ns, name, _r, _w in nodes]
        return sorted(out, key=lambda x: (x[1], x[0]))

    def _names_and_types(self, kinds: set[str]) -> list[tuple[str, list[str]]]:
        self._update()
        table: dict[str, set[str]] = defaultdict(set)
        with self._lock:
            for _kind, ep in self._endpoints.values():
                parsed = ros_topic_name_from_dds(ep.topic_name)
                if parsed is None or parsed[1] not in kinds:
                    continue
                ros_type = ros_type_name_from_dds(ep.type_name)
                if ros_type is None:
                    continue
                if parsed[1] != 'topic':
                    ros_type = ros_type.removesuffix('_Request').removesuffix('_Response')
                table[parsed[0]].add(ros_type)
        return sorted((k, sorted(v)) for k, v in table.items())

    def topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        return self._names_and_types({'topic'})

    def service_names_and_types(self) -> list[tuple[str, list[str]]]:
        return self._names_and_types({'request'})

    def endpoints(self, topic: str, kind: str) -> list[TopicEndpointInfo]:
        """Publishers (``kind='publisher'``) or subscriptions of a ROS topic."""
        self._update()
        out = []
        dds_name = 'rt' + topic
        with self._lock:
            for gid, (k, ep) in self._endpoints.items():
                if k != kind or ep.topic_name != dds_name:
                    continue
                name, ns = self._owner(gid, ep.participant_key.bytes)
                out.append(TopicEndpointInfo(
                    node_name=name, node_namespace=ns,
                    topic_type=ros_type_name_from_dds(ep.type_name) or ep.type_name,
                    endpoint_type='PUBLISHER' if kind == 'publisher' else 'SUBSCRIPTION',
                    endpoint_gid=gid, qos_profile=_qos_from_dds(ep.qos),
                    topic_type_hash=_user_data_hash(ep.qos)))
        return sorted(out, key=lambda e: (e.node_namespace, e.node_name, e.endpoint_gid))

    def node_endpoints(self, name: str, namespace: str) -> dict[str, list[tuple[str, str]]]:
        """Topics and services of a node: {'publishers': [(topic, type)], 'subscribers': ...,
        'services': ..., 'clients': ...}."""
        self._update()
        out: dict[str, set[tuple[str, str]]] = defaultdict(set)
        with self._lock:
            mine: set[bytes] = set()
            for nodes in self._participants.values():
                for ns, n, readers, writers in nodes:
                    if n == name and ns == namespace:
                        mine |= readers | writers
            for gid, (kind, ep) in self._endpoints.items():
                if gid not in mine:
                    continue
                parsed = ros_topic_name_from_dds(ep.topic_name)
                ros_type = ros_type_name_from_dds(ep.type_name)
                if parsed is None or ros_type is None:
                    continue
                topic, role = parsed
                srv_type = ros_type.removesuffix('_Request').removesuffix('_Response')
                if role == 'topic':
                    out['publishers' if kind == 'publisher' else 'subscribers'].add(
                        (topic, ros_type))
                elif role == 'request':
                    out['services' if kind == 'subscription' else 'clients'].add(
                        (topic, srv_type))
        return {k: sorted(v) for k, v in out.items()}
