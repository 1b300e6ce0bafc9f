"""``rclpy.publisher.Publisher``: publishes messages of one type on one topic.

Delivery paths:

* Across processes: DDS (raw CDR through :mod:`mindgrasp_ros.runtime.dds`).
* Inside one process (composition): a publisher hands the message object to the local
  subscriptions of the same topic, skipping serialisation; DDS readers ignore samples of their own
  participant (Cyclone's IgnoreLocal), so nothing is delivered twice. Subscribers must treat
  received messages as read-only, since in-process receivers may share one object.
"""

from __future__ import annotations

import threading
from collections import deque
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.entity import Entity, local_gid
from mindgrasp_ros.runtime.qos import DurabilityPolicy, QoSProfile
from mindgrasp_ros.typesupport import MessageTypeError, deserialize, serialize, type_name_of

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds.participant import DdsWriter
    from mindgrasp_ros.runtime.node import Node

__all__ = ['Delivery', 'Publisher']


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
        return self._writer.guid if self._writer else local_gid(self)

    @property
    def on_dds(self) -> bool:
        """Whether the publisher has a DDS writer (False in a DDS-less context)."""
        return self._writer is not None

    def retained(self) -> list[Delivery]:
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
        delivery = Delivery(self.type_name, msg, raw_bytes)
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


class Delivery:
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
