"""``rclpy.subscription.Subscription``: receives messages of one type on one topic, from DDS
and from the publishers of the same process (:class:`~mindgrasp_ros.runtime.publisher.Delivery`).
"""

from __future__ import annotations

import inspect
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.entity import Entity, local_gid
from mindgrasp_ros.runtime.qos import HistoryPolicy, QoSProfile
from mindgrasp_ros.typesupport import deserialize, type_name_of

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds.participant import DdsReader
    from mindgrasp_ros.runtime.node import Node
    from mindgrasp_ros.runtime.publisher import Delivery

__all__ = ['MessageInfo', 'Subscription']


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
        self._queue: deque[Delivery] = deque(maxlen=maxlen)
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
        return self._reader.guid if self._reader else local_gid(self)

    def enqueue(self, delivery: Delivery) -> None:
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
    try:
        params = [p for p in inspect.signature(callback).parameters.values()
                  if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    except (TypeError, ValueError):
        return False
    return len(params) >= 2 and params[1].default is inspect.Parameter.empty
