"""``rclpy.client.Client``: sends requests of one service type and completes a
:class:`~mindgrasp_ros.runtime.task.Future` with each reply."""

from __future__ import annotations

import itertools
import threading
import time
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.entity import Entity, local_gid
from mindgrasp_ros.runtime.qos import QoSProfile
from mindgrasp_ros.runtime.service import (
    endpoint_pair_id,
    pack_service,
    service_topics,
    unpack_service,
)
from mindgrasp_ros.runtime.task import Future
from mindgrasp_ros.typesupport import MessageTypeError, deserialize, serialize, type_name_of

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.node import Node

__all__ = ['Client']


class Client(Entity):
    """Calls a service (``rclpy.client.Client``)."""

    take_rank = 2

    _guids = itertools.count(1)

    def __init__(self, node: Node, srv_type: type, name: str, qos: QoSProfile,
                 callback_group: CallbackGroup | None) -> None:
        super().__init__(node, callback_group)
        self.srv_type = srv_type
        self.srv_name = name
        self.service_name = name
        self.qos_profile = qos
        self._req_type = type_name_of(srv_type.Request)
        self._res_type = type_name_of(srv_type.Response)
        req_topic, rep_topic = service_topics(name)
        dds = node.context.dds
        self._writer = self._reader = None
        self._guid = next(Client._guids)
        if dds is not None:
            # as rmw_cyclonedds: with this id a server (real rclpy's too) waits for this
            # client's reply reader before it answers, instead of answering into the void
            ident = f'clientid={endpoint_pair_id(dds)};'
            self._writer = dds.create_writer(req_topic, self._req_type, qos,
                                             service_role='request', extra_user_data=ident)
            self._reader = dds.create_reader(rep_topic, self._res_type, qos,
                                             service_role='reply', extra_user_data=ident)
            # unique across processes: derived from the request writer's DDS GUID
            self._guid ^= int.from_bytes(self._writer.guid[:8], 'little')
        self._seq = itertools.count(1)
        self._pending: dict[int, Future] = {}
        self._lock = threading.Lock()

    @property
    def gid(self) -> bytes:
        return self._writer.guid if self._writer else local_gid(self)

    @property
    def reply_gid(self) -> bytes:
        return self._reader.guid if self._reader else local_gid(self)

    @property
    def request_type_name(self) -> str:
        """The request's type name (``pkg/srv/Name_Request``)."""
        return self._req_type

    def service_is_ready(self) -> bool:
        """A server's request reader and its reply writer are both matched (paired by their
        ``serviceid``, as rmw_cyclonedds' ``rmw_service_server_is_available`` pairs them; any
        reader and writer for servers that do not say their id)."""
        if self._writer is None:
            return self.srv_name in self.node.context.intra.services
        servers = self._writer.matched_user_data('serviceid')
        if servers:
            return bool(servers & self._reader.matched_user_data('serviceid'))
        return self._writer.matched_count() > 0 and self._reader.matched_count() > 0

    def wait_for_service(self, timeout_sec: float | None = None) -> bool:
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        while not self.service_is_ready():
            if self.node.context.is_shutdown():
                return False
            if deadline is not None and time.monotonic() >= deadline:
                return False
            time.sleep(0.01)
        return True

    def call_async(self, request: Any) -> Future:
        if type_name_of(request) != self._req_type:
            msg = (f"Client of '{self.srv_name}' sends {self._req_type}, but was given "
                   f'{type_name_of(request)}.')
            raise MessageTypeError(msg)
        future = Future()
        seq = next(self._seq)
        with self._lock:
            self._pending[seq] = future
        future.add_done_callback(lambda f: self._forget(seq, f))
        if self._writer is None:
            service = self.node.context.intra.services.get(self.srv_name)
            if service is None:
                future.set_exception(RuntimeError(f"No service '{self.srv_name}' in process."))
            else:
                service.enqueue_local(request, future)
            return future
        self._writer.write(pack_service(self._guid, seq, serialize(request, self._req_type)))
        return future

    def _forget(self, seq: int, future: Future) -> None:
        if future.cancelled():
            with self._lock:
                self._pending.pop(seq, None)

    def call(self, request: Any, timeout_sec: float | None = None) -> Any:
        """Blocking call; another thread must spin this node (as in rclpy)."""
        future = self.call_async(request)
        if not future.wait(timeout_sec):
            future.cancel()
            msg = f"Service '{self.srv_name}' did not answer within {timeout_sec} s."
            raise TimeoutError(msg)
        return future.result()

    def remove_pending_request(self, future: Future) -> None:
        with self._lock:
            for seq, f in list(self._pending.items()):
                if f is future:
                    del self._pending[seq]

    def take(self, dds: bool = True) -> list[tuple[Future, Any]]:
        out: list[tuple[Future, Any]] = []
        if self._reader is None or not dds:
            return out
        for data, _info in self._reader.take(64):
            try:
                guid, seq, payload = unpack_service(data)
            except ValueError:
                continue
            if guid != self._guid:
                continue  # a reply to another client of the same service
            with self._lock:
                future = self._pending.pop(seq, None)
            if future is None:
                continue
            try:
                out.append((future, deserialize(payload, self._res_type)))
            except Exception as exc:
                future.set_exception(exc)
        return out

    def execute(self, item: tuple[Future, Any]) -> None:
        future, response = item
        if not future.done():
            future.set_result(response)

    def destroy(self) -> None:
        dds = self.node.context.dds
        if dds is not None and self._reader is not None:
            dds.delete_reader(self._reader)
            dds.delete_writer(self._writer)
