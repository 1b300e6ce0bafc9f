"""``rclpy.context.Context``: one per process normally; owns the DDS participant.

A context made with ``transport='intra'`` has no DDS at all: its nodes talk only in-process. The
lock-step runner of :mod:`mindgrasp_ros.graph` uses that for deterministic batch runs.
"""

from __future__ import annotations

import os
import sys
import threading
from collections import defaultdict
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.arguments import RosArguments, parse_ros_args
from mindgrasp_ros.runtime.exceptions import NotInitializedException, RCLError
from mindgrasp_ros.runtime.logging import get_logger, set_logger_level
from mindgrasp_ros.runtime.qos import QoSProfile

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds.discovery import GraphCache
    from mindgrasp_ros.runtime.dds.participant import DdsParticipant, DdsWriter
    from mindgrasp_ros.runtime.intra_graph import IntraGraph
    from mindgrasp_ros.runtime.node import Node
    from mindgrasp_ros.runtime.publisher import Delivery, Publisher
    from mindgrasp_ros.runtime.subscription import Subscription

__all__ = ['Context']


class IntraProcess:
    """In-process delivery between publishers and subscriptions of one context."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._pubs: dict[str, list[Publisher]] = defaultdict(list)
        self._subs: dict[str, list[Subscription]] = defaultdict(list)
        self._warned: set[tuple[str, str]] = set()
        self.services: dict[str, Any] = {}  # in-process services of DDS-less contexts

    def add_publisher(self, pub: Publisher) -> None:
        with self._lock:
            self._pubs[pub.topic_name].append(pub)

    def remove_publisher(self, pub: Publisher) -> None:
        with self._lock:
            if pub in self._pubs.get(pub.topic_name, []):
                self._pubs[pub.topic_name].remove(pub)

    def add_subscription(self, sub: Subscription) -> None:
        with self._lock:
            self._subs[sub.topic_name].append(sub)
            pubs = list(self._pubs.get(sub.topic_name, []))
        # transient local: a late joiner gets what local publishers kept
        from mindgrasp_ros.runtime.qos import DurabilityPolicy

        if sub.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL:
            for pub in pubs:
                retained = pub.retained()
                if retained and self._compatible(pub, sub):
                    for delivery in retained:
                        sub.enqueue(delivery)

    def remove_subscription(self, sub: Subscription) -> None:
        with self._lock:
            if sub in self._subs.get(sub.topic_name, []):
                self._subs[sub.topic_name].remove(sub)

    def _compatible(self, pub: Publisher, sub: Subscription) -> bool:
        if pub.type_name != sub.type_name:
            key = (pub.topic_name, sub.type_name)
            if key not in self._warned:
                self._warned.add(key)
                get_logger('mindgrasp_ros').warning(
                    f"Topic '{pub.topic_name}': a publisher of {pub.type_name} and a "
                    f'subscription of {sub.type_name} in one process do not match; use one type.')
            return False
        return sub.qos_profile.is_compatible_with(pub.qos_profile)

    def deliver(self, pub: Publisher, delivery: Delivery) -> None:
        subs = self._subs.get(pub.topic_name)
        if not subs:
            return
        for sub in list(subs):
            if self._compatible(pub, sub):
                if sub.raw:
                    # serialised now (once per publish, shared by every raw receiver), so the
                    # bytes are the message as published even if the publisher reuses the object
                    delivery.raw()
                sub.enqueue(delivery)

    def count_subscriptions(self, topic: str) -> int:
        return len(self._subs.get(topic, []))

    def count_publishers(self, topic: str) -> int:
        return len(self._pubs.get(topic, []))

    def topics(self) -> dict[str, set[str]]:
        out: dict[str, set[str]] = defaultdict(set)
        with self._lock:
            for table in (self._pubs, self._subs):
                for topic, entities in table.items():
                    for e in entities:
                        out[topic].add(e.type_name)
        return out


class Context:
    """Initialisation state, arguments, nodes and transport of one ROS 'process'."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._ok = False
        self._shutdown_callbacks: list[Callable[[], None]] = []
        self.args = RosArguments()
        self.dds: DdsParticipant | None = None
        self.transport = 'dds'
        self.intra = IntraProcess()
        self.nodes: list[Node] = []
        self._discovery_writer: DdsWriter | None = None
        self._graph: GraphCache | IntraGraph | None = None
        self.domain_id = 0

    def init(self, args: list[str] | None = None, *, domain_id: int | None = None,
             transport: str = 'dds') -> None:
        with self._lock:
            if self._ok:
                msg = 'Context.init() called twice: call rclpy.shutdown() first.'
                raise RCLError(msg)
            argv = list(sys.argv if args is None else args)
            self.args = parse_ros_args(argv)
            for logger, level in self.args.log_levels:
                set_logger_level(logger, level)
            if transport not in ('dds', 'intra'):
                msg = f"transport must be 'dds' or 'intra', not {transport!r}."
                raise RCLError(msg)
            self.transport = transport
            if transport == 'dds':
                from mindgrasp_ros.runtime.dds.participant import DdsParticipant

                self.dds = DdsParticipant(domain_id)
                self.domain_id = self.dds.domain_id
            self._ok = True

    def ok(self) -> bool:
        return self._ok

    def is_shutdown(self) -> bool:
        return not self._ok

    def require_dds(self, what: str) -> DdsParticipant:
        if self.dds is None:
            if not self._ok:
                raise NotInitializedException()
            msg = (f'{what} need DDS, and this context was initialised with transport='
                   f"'{self.transport}'.")
            raise RCLError(msg)
        return self.dds

    def on_shutdown(self, callback: Callable[[], None]) -> None:
        self._shutdown_callbacks.append(callback)

    def shutdown(self) -> None:
        with self._lock:
            if not self._ok:
                raise NotInitializedException()
            self._ok = False
            callbacks, self._shutdown_callbacks = self._shutdown_callbacks, []
        for cb in callbacks:
            try:
                cb()
            except Exception as exc:
                get_logger('mindgrasp_ros').error(f'Shutdown callback failed: {exc}')
        for node in list(self.nodes):
            node.wake_executor()
            node.context_shutdown()
        with self._lock:
            self.nodes.clear()
            self.intra = IntraProcess()
            if self._graph is not None:
                self._graph.close()
                self._graph = None
            if self.dds is not None:
                dds, self.dds = self.dds, None
                self._discovery_writer = None
                try:
                    dds.close()
                except Exception:
                    pass

    def try_shutdown(self) -> None:
        if self._ok:
            self.shutdown()

    # ------------------------------------------------------------------ nodes and discovery
    def add_node(self, node: Node) -> None:
        with self._lock:
            self.nodes.append(node)

    def node_list(self) -> list[Node]:
        """The nodes of this context now (a copy, taken under the context's lock)."""
        with self._lock:
            return list(self.nodes)

    def remove_node(self, node: Node) -> None:
        with self._lock:
            if node in self.nodes:
                self.nodes.remove(node)
        self.publish_discovery_info()

    def publish_discovery_info(self) -> None:
        """Publish ``ros_discovery_info`` (rmw_dds_common) so ROS 2 tools see our nodes."""
        if self.dds is None or not self._ok:
            return
        from mindgrasp_ros.runtime.qos import DurabilityPolicy
        from mindgrasp_ros.typesupport import get_message_class, serialize

        with self._lock:
            if self._discovery_writer is None:
                qos = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
                self._discovery_writer = self.dds.create_writer(
                    'ros_discovery_info', 'rmw_dds_common/msg/ParticipantEntitiesInfo', qos)
            gid_cls = get_message_class('rmw_dds_common/msg/Gid')
            info_cls = get_message_class('rmw_dds_common/msg/NodeEntitiesInfo')
            infos = []
            for node in self.nodes:
                readers, writers = node.dds_gids()
                infos.append(info_cls(
                    node_namespace=node.get_namespace(), node_name=node.get_name(),
                    reader_gid_seq=[gid_cls(data=_gid16(g)) for g in readers],
                    writer_gid_seq=[gid_cls(data=_gid16(g)) for g in writers]))
            msg = get_message_class('rmw_dds_common/msg/ParticipantEntitiesInfo')(
                gid=gid_cls(data=_gid16(self.dds.guid)), node_entities_info_seq=infos)
            self._discovery_writer.write(serialize(msg))

    @property
    def graph(self) -> GraphCache | IntraGraph:
        """Graph introspection (created on first use): of the domain through DDS discovery, or,
        in a DDS-less context, of this context's own nodes (:mod:`.intra_graph`)."""
        with self._lock:
            if self._graph is None:
                if self.transport == 'intra':
                    if not self._ok:
                        raise NotInitializedException()
                    from mindgrasp_ros.runtime.intra_graph import IntraGraph

                    self._graph = IntraGraph(self)
                else:
                    from mindgrasp_ros.runtime.dds.discovery import GraphCache

                    self._graph = GraphCache(self.require_dds('Graph introspection'))
            return self._graph

    @property
    def pid(self) -> int:
        return os.getpid()


def _gid16(gid: bytes) -> bytes:
    return (bytes(gid) + b'\0' * 16)[:16]
