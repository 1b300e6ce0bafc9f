"""The base of every entity an executor runs (publishers, subscriptions, timers, services,
clients, guard conditions): its callback group, its place in a node's round and its GID."""

from __future__ import annotations

import itertools
import os
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.callback_groups import CallbackGroup

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds.participant import DdsReader
    from mindgrasp_ros.runtime.node import Node

__all__ = ['Entity', 'local_gid']

_creation_numbers = itertools.count()


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
        self._gid: bytes | None = None   # a local GID, made when first asked (local_gid)

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


_local_ids = itertools.count(1)


def local_gid(entity: Entity) -> bytes:
    gid = entity._gid
    if gid is None:
        gid = os.getpid().to_bytes(4, 'little') + next(_local_ids).to_bytes(12, 'little')
        entity._gid = gid
    return gid
