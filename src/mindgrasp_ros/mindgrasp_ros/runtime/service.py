"""``rclpy.service.Service``: answers requests of one service type, from DDS (rmw_cyclonedds'
request/reply topics) and from clients of the same process.

Request and reply samples carry rmw_cyclonedds' header before the payload: uint64 client guid,
int64 sequence number (:func:`pack_service`, :func:`unpack_service`, shared with
:mod:`mindgrasp_ros.runtime.client`).
"""

from __future__ import annotations

import itertools
import struct
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.entity import Entity, local_gid
from mindgrasp_ros.runtime.qos import QoSProfile
from mindgrasp_ros.runtime.task import Future
from mindgrasp_ros.typesupport import deserialize, serialize, type_name_of

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.node import Node

__all__ = ['REPLY_READER_WAIT_S', 'Service', 'endpoint_pair_id', 'pack_service', 'service_topics',
           'unpack_service']

_CDR_HEADER = b'\x00\x01\x00\x00'
#: longest a service waits for a new caller's reply reader to be discovered (s)
REPLY_READER_WAIT_S = 5.0


def pack_service(guid: int, seq: int, payload_cdr: bytes) -> bytes:
    return _CDR_HEADER + struct.pack('<Qq', guid, seq) + payload_cdr[4:]


def unpack_service(data: bytes) -> tuple[int, int, bytes]:
    if len(data) < 20:
        msg = f'service sample of {len(data)} bytes is too short for the request header'
        raise ValueError(msg)
    little = data[1] == 1
    guid, seq = struct.unpack('<Qq' if little else '>Qq', data[4:20])
    return guid, seq, data[:4] + data[20:]


_pair_ids = itertools.count(1)


def endpoint_pair_id(dds: Any) -> str:
    """An id unique on the domain for a client's or a service's two endpoints: the
    participant's GUID and a counter (rmw_cyclonedds writes its own 16-byte id the same way)."""
    return f'{dds.participant.guid.hex}.{next(_pair_ids)}'


def service_topics(name: str) -> tuple[str, str]:
    return f'rq{name}Request', f'rr{name}Reply'


class Service(Entity):
    """Serves requests of one service type (``rclpy.service.Service``)."""

    take_rank = 1

    def __init__(self, node: Node, srv_type: type, name: str, callback: Callable,
                 qos: QoSProfile, callback_group: CallbackGroup | None) -> None:
        super().__init__(node, callback_group)
        self.srv_type = srv_type
        self.srv_name = name
        self.service_name = name
        self.callback = callback
        self.qos_profile = qos
        self._req_type = type_name_of(srv_type.Request)
        self._res_type = type_name_of(srv_type.Response)
        req_topic, rep_topic = service_topics(name)
        dds = node.context.dds
        self._reader = self._writer = None
        # in-process requests (always used in DDS-less contexts): (request, future) pairs
        self._local: deque[tuple[Any, Future]] = deque()
        if dds is not None:
            # rmw_cyclonedds pairs a service's request reader and reply writer by this id
            ident = f'serviceid={endpoint_pair_id(dds)};'
            self._reader = dds.create_reader(req_topic, self._req_type, qos,
                                             service_role='request', extra_user_data=ident)
            self._writer = dds.create_writer(rep_topic, self._res_type, qos,
                                             service_role='reply', extra_user_data=ident)
        else:
            node.context.intra.services[name] = self

    @property
    def gid(self) -> bytes:
        return self._reader.guid if self._reader else local_gid(self)

    @property
    def reply_gid(self) -> bytes:
        return self._writer.guid if self._writer else local_gid(self)

    @property
    def request_type_name(self) -> str:
        """The request's type name (``pkg/srv/Name_Request``)."""
        return self._req_type

    def enqueue_local(self, request: Any, future: Future) -> None:
        self._local.append((request, future))
        self.node.wake_executor(self)

    def has_data_hint(self) -> bool:
        """Whether in-process requests are waiting (see :meth:`Entity.has_data_hint`)."""
        return bool(self._local)

    def take(self, dds: bool = True) -> list[tuple[Any, int, Any, int]]:
        out: list[Any] = []
        while self._local:
            request, future = self._local.popleft()
            out.append((future, 0, request, 0))
        if self._reader is None or not dds:
            return out
        for data, info in self._reader.take(64):
            try:
                guid, seq, payload = unpack_service(data)
                out.append((guid, seq, deserialize(payload, self._req_type),
                            info.publication_handle))
            except Exception as exc:
                self.node.get_logger().warning(
                    f"Dropped a malformed request on service '{self.srv_name}': {exc}")
        return out

    def execute(self, item: tuple[Any, int, Any, int]) -> None:
        guid, seq, request, request_writer = item
        response = self.srv_type.Response()
        result = self.callback(request, response)
        if result is None:
            self.node.get_logger().error(
                f"Service callback of '{self.srv_name}' returned None; it must return the "
                'response object.')
            return
        if isinstance(guid, Future):  # an in-process call
            guid.set_result(result)
            return
        self._wait_for_reply_reader(request_writer)
        self._writer.write(pack_service(guid, seq, serialize(result, self._res_type)))

    def _wait_for_reply_reader(self, request_writer: int) -> None:
        """Wait until the caller's reply reader is matched, as rmw_cyclonedds does before it
        sends a response. A client that saw this service (wait_for_service) may call before
        this side has discovered the client's reply reader; a reply written then reaches no one
        and the call never completes. Clients are counted per participant: every request writer
        of the caller's participant must have a reply reader there. Bounded: a client that has
        gone, or that is still unmatched after the deadline, gets the reply written anyway."""
        deadline = time.monotonic() + REPLY_READER_WAIT_S
        while True:
            participant = self._reader.writer_participant(request_writer)
            if participant is None:
                return      # the client has gone (or the request came from no known writer)
            if self._writer.readers_of(participant) >= self._reader.writers_of(participant):
                return
            if time.monotonic() >= deadline:
                self.node.get_logger().warning(
                    f"Service '{self.srv_name}': the caller's reply reader is still not "
                    f'discovered after {REPLY_READER_WAIT_S:.0f} s; replying anyway (the reply '
                    'may be lost).')
                return
            time.sleep(0.005)

    def destroy(self) -> None:
        dds = self.node.context.dds
        self.node.context.intra.services.pop(self.srv_name, None)
        if dds is not None and self._reader is not None:
            dds.delete_reader(self._reader)
            dds.delete_writer(self._writer)
