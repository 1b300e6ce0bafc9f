"""Publishers, subscriptions, timers, services, clients and guard conditions.

Delivery paths:

* Across processes: DDS (raw CDR through :mod:`mindgrasp_ros.runtime.dds`).
* Inside one process (composition): a publisher hands the message object to the local
  subscriptions of the same topic, skipping serialisation; DDS readers ignore samples of their own
  participant (Cyclone's IgnoreLocal), so nothing is delivered twice. Subscribers must treat
  received messages as read-only, since in-process receivers may share one object.
"""

from __future__ import annotations

import itertools
import os
import struct
import threading
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.clock import Clock
from mindgrasp_ros.runtime.qos import DurabilityPolicy, HistoryPolicy, QoSProfile
from mindgrasp_ros.runtime.task import Future
from mindgrasp_ros.typesupport import MessageTypeError, deserialize, serialize, type_name_of

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds import DdsReader, DdsWriter
    from mindgrasp_ros.runtime.node import Node

__all__ = ['Client', 'GuardCondition', 'Publisher', 'Service', 'Subscription', 'Timer']

_CDR_HEADER = b'\x00\x01\x00\x00'
_creation_numbers = itertools.count()
#: longest a service waits for a new caller's reply reader to be discovered (s)
REPLY_READER_WAIT_S = 5.0


class Entity:
    """Something an executor can run: it has a callback group and may be busy."""

    #: read by its owner, never by executors (only a subscription can be; see Subscription)
    polled = False
    #: where executors take this kind in a node's round: subscriptions, services, clients, guard
    #: conditions (timers come first, on their own)
    take_rank = 0
    _reader: DdsReader | None = None   # a subscription's, a service's requests, a client's replies

    def __init__(self, node: Node, callback_group: CallbackGroup | None) -> None:
        self.node = node
        #: (take_rank, creation number): the order in which an executor takes ready entities,
        #: the order of the node's entity lists
        self.take_order = (self.take_rank, next(_creation_numbers))
        self.callback_group = callback_group or node.default_callback_group
        self.callback_group.add_entity(self)
        #: set by executors while a callback of this entity runs
        self.busy = False
        self._gid: bytes | None = None   # a local GID, made when first asked (_local_gid)

    @property
    def dds_reader(self) -> DdsReader | None:
        """The DDS reader whose samples :meth:`take` reads (None in a DDS-less context and for
        entities without one): what an executor's wait set watches."""
        return self._reader

    def has_data_hint(self) -> bool:
        """Whether in-process work is waiting for :meth:`take` (DDS samples are announced by the
        executor's wait set instead). Executors ask this before they take, as rclpy's ask the
        wait set; entities that queue nothing in-process answer False."""
        return False

    def take(self, dds: bool = True) -> list[Any]:
        """The work items waiting for :meth:`execute`, oldest first (``dds`` False: only the
        in-process ones)."""
        return []

    def destroy(self) -> None:
        """Free the entity's resources (called by the node's ``destroy_*``)."""


# --------------------------------------------------------------------------- topics

class Publisher(Entity):
    """Publishes messages of one type on one topic (``rclpy.publisher.Publisher``)."""

    def __init__(self, node: Node, msg_type: type, topic: str, qos: QoSProfile,
                 callback_group: CallbackGroup | None, *, raw: bool = False,
                 type_name: str | None = None) -> None:
        super().__init__(node, callback_group)
        self.msg_type = msg_type
        self.type_name = type_name or type_name_of(msg_type)
        self.topic_name = topic
        self.qos_profile = qos
        self.raw = raw
        self._writer: DdsWriter | None = None
        ctx = node.context
        if ctx.dds is not None:
            self._writer = ctx.dds.create_writer('rt' + topic, self.type_name, qos)
        # transient-local history for in-process late joiners
        self._history: deque[Any] | None = (
            deque(maxlen=max(1, qos.depth)) if qos.durability == DurabilityPolicy.TRANSIENT_LOCAL
            else None)
        ctx.intra.add_publisher(self)

    @property
    def topic(self) -> str:
        return self.topic_name

    @property
    def gid(self) -> bytes:
        return self._writer.guid if self._writer else _local_gid(self)

    @property
    def on_dds(self) -> bool:
        """Whether the publisher has a DDS writer (False in a DDS-less context)."""
        return self._writer is not None

    def retained(self) -> list[_Delivery]:
        """What a transient-local publisher keeps for late-joining subscriptions, oldest
        first (empty for a volatile one)."""
        return list(self._history or ())

    def publish(self, msg: Any) -> None:
        """Publish a message (or CDR bytes, for a publisher created with ``raw=True``)."""
        raw_bytes: bytes | None = None
        if isinstance(msg, (bytes, bytearray, memoryview)):
            if not self.raw:
                text = (f"Publisher on '{self.topic_name}' got bytes; create it with raw=True "
                        'to publish serialized CDR.')
                raise TypeError(text)
            raw_bytes = bytes(msg)
            msg = None
        elif (type(msg) is not self.msg_type
              and getattr(type(msg), '__msgtype__', None) != self.type_name):
            got = getattr(type(msg), '__msgtype__', type(msg).__name__)
            text = (f"Publisher on '{self.topic_name}' carries {self.type_name}, but was "
                    f'given {got}; publish a {self.type_name} message or create another '
                    'publisher.')
            raise MessageTypeError(text)
        ctx = self.node.context
        if ctx.is_shutdown():
            return
        delivery = _Delivery(self.type_name, msg, raw_bytes)
        if self._writer is not None and (
                self._history is not None or self._writer.matched_count() > 0):
            self._writer.write(delivery.raw())
        if self._history is not None:
            self._history.append(delivery)
        ctx.intra.deliver(self, delivery)

    def get_subscription_count(self) -> int:
        remote = self._writer.matched_count() if self._writer else 0
        return remote + self.node.context.intra.count_subscriptions(self.topic_name)

    def wait_for_all_acked(self, timeout: Any = None) -> bool:
        if self._writer is None:
            return True
        ns = timeout.nanoseconds if timeout is not None else 10_000_000_000
        try:
            return bool(self._writer.writer.wait_for_acks(ns))
        except Exception:
            return False

    def destroy(self) -> None:
        ctx = self.node.context
        ctx.intra.remove_publisher(self)
        if self._writer is not None and ctx.dds is not None:
            ctx.dds.delete_writer(self._writer)
            self._writer = None


class _Delivery:
    """One published message, serialised or deserialised lazily and at most once."""

    __slots__ = ('_lock', '_msg', '_raw', 'type_name')

    def __init__(self, type_name: str, msg: Any, raw: bytes | None) -> None:
        self.type_name = type_name
        self._msg = msg
        self._raw = raw
        self._lock = threading.Lock()

    def raw(self) -> bytes:
        if self._raw is None:
            with self._lock:
                if self._raw is None:
                    self._raw = serialize(self._msg, self.type_name)
        return self._raw

    def message(self) -> Any:
        if self._msg is None:
            with self._lock:
                if self._msg is None:
                    self._msg = deserialize(self._raw, self.type_name)
        return self._msg


class MessageInfo(dict):
    """Per-message metadata passed to callbacks that take two arguments (like rclpy)."""


class Subscription(Entity):
    """Receives messages of one type on one topic (``rclpy.subscription.Subscription``)."""

    def __init__(self, node: Node, msg_type: type | None, topic: str, callback: Callable,
                 qos: QoSProfile, callback_group: CallbackGroup | None, *, raw: bool = False,
                 type_name: str | None = None, polled: bool = False) -> None:
        super().__init__(node, callback_group)
        #: executors leave it alone: its owner reads it with :meth:`take` (see
        #: ``Node.create_subscription``)
        self.polled = polled
        self.msg_type = msg_type
        self.type_name = type_name or type_name_of(msg_type)
        self.topic_name = topic
        self.callback = callback
        self.qos_profile = qos
        self.raw = raw
        self._takes_info = _accepts_two_args(callback)
        maxlen = None if qos.history == HistoryPolicy.KEEP_ALL else max(1, qos.depth)
        self._queue: deque[_Delivery] = deque(maxlen=maxlen)
        self._reader: DdsReader | None = None
        self._local_lost = 0
        self.malformed_count = 0
        ctx = node.context
        if ctx.dds is not None:
            self._reader = ctx.dds.create_reader('rt' + topic, self.type_name, qos,
                                                 ignore_local=True)
        ctx.intra.add_subscription(self)

    @property
    def topic(self) -> str:
        return self.topic_name

    @property
    def gid(self) -> bytes:
        return self._reader.guid if self._reader else _local_gid(self)

    def enqueue(self, delivery: _Delivery) -> None:
        """Queue an in-process delivery for the callback (the context's intra-process path)."""
        if self._queue.maxlen is not None and len(self._queue) == self._queue.maxlen:
            self._local_lost += 1  # KEEP_LAST: the oldest undelivered message is dropped
        self._queue.append(delivery)
        self.node.wake_executor(self)

    @property
    def messages_lost(self) -> int:
        """Messages that never reached the callback: DDS-reported losses plus in-process
        queue overflows (not in rclpy, which reports these through event callbacks)."""
        remote = self._reader.lost if self._reader is not None else 0
        return remote + self._local_lost

    def take(self, dds: bool = True) -> list[tuple[Any, MessageInfo]]:
        """Everything that has arrived: (message or bytes, info) pairs, oldest first (``dds``
        False: only the in-process deliveries, the executor saw no DDS data). Executors call it;
        so does the owner of a ``polled`` subscription, as ``rclcpp::Subscription::take``.
        ``info['source_timestamp']``: the publisher's write time, ns (DDS samples only)."""
        out: list[tuple[Any, MessageInfo]] = []
        while self._queue:
            delivery = self._queue.popleft()
            try:
                out.append((delivery.raw() if self.raw else delivery.message(), MessageInfo()))
            except Exception as exc:
                self._report_malformed(exc)
        if self._reader is not None and dds:
            for data, info in self._reader.take(256):
                if self.raw:
                    out.append((data, MessageInfo(source_timestamp=info.source_timestamp)))
                    continue
                try:
                    msg = deserialize(data, self.type_name)
                except Exception as exc:
                    self._report_malformed(exc)
                    continue
                out.append((msg, MessageInfo(source_timestamp=info.source_timestamp)))
        return out

    def _report_malformed(self, exc: Exception) -> None:
        self.malformed_count += 1
        self.node.get_logger().warning(
            f"Dropped a malformed {self.type_name} sample on '{self.topic_name}' "
            f'({self.malformed_count} so far): {exc}', throttle_duration_sec=5.0)

    def has_data_hint(self) -> bool:
        """Whether in-process deliveries wait in the queue (see :meth:`Entity.has_data_hint`)."""
        return bool(self._queue)

    def execute(self, item: tuple[Any, MessageInfo]) -> None:
        msg, info = item
        if self._takes_info:
            self.callback(msg, info)
        else:
            self.callback(msg)

    def get_publisher_count(self) -> int:
        remote = self._reader.matched_count() if self._reader else 0
        return remote + self.node.context.intra.count_publishers(self.topic_name)

    def destroy(self) -> None:
        ctx = self.node.context
        ctx.intra.remove_subscription(self)
        if self._reader is not None and ctx.dds is not None:
            ctx.dds.delete_reader(self._reader)
            self._reader = None


def _accepts_two_args(callback: Callable) -> bool:
    import inspect

    try:
        params = [p for p in inspect.signature(callback).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):
        return False
    return len(params) >= 2 and params[1].default is inspect.Parameter.empty


_local_ids = itertools.count(1)


def _local_gid(entity: Entity) -> bytes:
    gid = entity._gid
    if gid is None:
        gid = os.getpid().to_bytes(4, 'little') + next(_local_ids).to_bytes(12, 'little')
        entity._gid = gid
    return gid


# --------------------------------------------------------------------------- timers

class Timer(Entity):
    """Calls back every ``timer_period_ns`` of its clock (ROS time follows /clock)."""

    def __init__(self, node: Node, period_sec: float, callback: Callable | None,
                 callback_group: CallbackGroup | None, clock: Clock,
                 autostart: bool = True) -> None:
        super().__init__(node, callback_group)
        if not period_sec >= 0:
            msg = f'Timer period must be a non-negative number of seconds, not {period_sec!r}.'
            raise ValueError(msg)
        self.timer_period_ns = round(period_sec * 1e9)
        self.callback = callback
        self.clock = clock
        self._canceled = not autostart
        self._next_ns = clock.now().nanoseconds + self.timer_period_ns
        self._last_ns = clock.now().nanoseconds

    def is_canceled(self) -> bool:
        """Whether the timer is canceled (a method, as rclpy's)."""
        return self._canceled

    def cancel(self) -> None:
        self._canceled = True

    def reset(self) -> None:
        self._canceled = False
        now = self.clock.now().nanoseconds
        self._next_ns = now + self.timer_period_ns
        self._last_ns = now
        self.node.wake_executor()

    def is_ready(self) -> bool:
        """Whether a period has elapsed since the last call (``rclpy.timer.Timer.is_ready``);
        the executor then takes it with :meth:`call_timer`."""
        if self._canceled:
            return False
        now = self.clock.now_ns()
        if now < self._last_ns:  # time jumped back (sim time restarted): restart the period
            self._last_ns = now
            self._next_ns = now + self.timer_period_ns
            return False
        return now >= self._next_ns

    def time_until_next_call(self) -> int | None:
        """Nanoseconds until due (None when canceled)."""
        if self._canceled:
            return None
        return max(0, self._next_ns - self.clock.now_ns())

    def time_since_last_call(self) -> int:
        return self.clock.now_ns() - self._last_ns

    def call_timer(self) -> None:
        """Take a ready timer: its next period starts now (the executor then runs
        :meth:`execute`), as rcl's ``rcl_timer_call`` behind rclpy's ``_take_timer``."""
        now = self.clock.now_ns()
        self._last_ns = now
        self._next_ns += self.timer_period_ns
        if self._next_ns <= now:  # missed periods: skip them, as rcl does
            missed = (now - self._next_ns) // max(1, self.timer_period_ns) + 1
            self._next_ns += missed * self.timer_period_ns

    def execute(self, _item: object = None) -> None:
        if self.callback is not None:
            self.callback()


class GuardCondition(Entity):
    """Runs its callback on the executor after :meth:`trigger`."""

    take_rank = 3

    def __init__(self, node: Node, callback: Callable,
                 callback_group: CallbackGroup | None) -> None:
        super().__init__(node, callback_group)
        self.callback = callback
        self._triggered = False

    def trigger(self) -> None:
        self._triggered = True
        self.node.wake_executor(self)

    def has_data_hint(self) -> bool:
        """Whether :meth:`trigger` was called since the executor last took the guard."""
        return self._triggered

    def take(self, dds: bool = True) -> list[None]:
        """One work item after a trigger (clearing it), else none."""
        if not self._triggered:
            return []
        self._triggered = False
        return [None]

    def execute(self, _item: object = None) -> None:
        self.callback()


# --------------------------------------------------------------------------- services
# Request and reply samples carry rmw_cyclonedds' header before the payload:
# uint64 client guid, int64 sequence number. Both are 8-aligned, so the payload's CDR alignment
# is the same as on its own.

def _pack_service(guid: int, seq: int, payload_cdr: bytes) -> bytes:
    return _CDR_HEADER + struct.pack('<Qq', guid, seq) + payload_cdr[4:]


def _unpack_service(data: bytes) -> tuple[int, int, bytes]:
    if len(data) < 20:
        msg = f'service sample of {len(data)} bytes is too short for the request header'
        raise ValueError(msg)
    little = data[1] == 1
    guid, seq = struct.unpack('<Qq' if little else '>Qq', data[4:20])
    return guid, seq, data[:4] + data[20:]


_pair_ids = itertools.count(1)


def _endpoint_pair_id(dds: Any) -> str:
    """An id unique on the domain for a client's or a service's two endpoints: the
    participant's GUID and a counter (rmw_cyclonedds writes its own 16-byte id the same way)."""
    return f'{dds.participant.guid.hex}.{next(_pair_ids)}'


def _service_topics(name: str) -> tuple[str, str]:
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
        req_topic, rep_topic = _service_topics(name)
        dds = node.context.dds
        self._reader = self._writer = None
        # in-process requests (always used in DDS-less contexts): (request, future) pairs
        self._local: deque[tuple[Any, Future]] = deque()
        if dds is not None:
            # rmw_cyclonedds pairs a service's request reader and reply writer by this id
            ident = f'serviceid={_endpoint_pair_id(dds)};'
            self._reader = dds.create_reader(req_topic, self._req_type, qos,
                                             service_role='request', extra_user_data=ident)
            self._writer = dds.create_writer(rep_topic, self._res_type, qos,
                                             service_role='reply', extra_user_data=ident)
        else:
            node.context.intra.services[name] = self

    @property
    def gid(self) -> bytes:
        return self._reader.guid if self._reader else _local_gid(self)

    @property
    def reply_gid(self) -> bytes:
        return self._writer.guid if self._writer else _local_gid(self)

    @property
    def request_type_name(self) -> str:
        """The request's type name (``pkg/srv/Name_Request``)."""
        return self._req_type

    def _enqueue_local(self, request: Any, future: Future) -> None:
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
                guid, seq, payload = _unpack_service(data)
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
        self._writer.write(_pack_service(guid, seq, serialize(result, self._res_type)))

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
        req_topic, rep_topic = _service_topics(name)
        dds = node.context.dds
        self._writer = self._reader = None
        self._guid = next(Client._guids)
        if dds is not None:
            # as rmw_cyclonedds: with this id a server (real rclpy's too) waits for this
            # client's reply reader before it answers, instead of answering into the void
            ident = f'clientid={_endpoint_pair_id(dds)};'
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
        return self._writer.guid if self._writer else _local_gid(self)

    @property
    def reply_gid(self) -> bytes:
        return self._reader.guid if self._reader else _local_gid(self)

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
                service._enqueue_local(request, future)
            return future
        self._writer.write(_pack_service(self._guid, seq, serialize(request, self._req_type)))
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
                guid, seq, payload = _unpack_service(data)
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
