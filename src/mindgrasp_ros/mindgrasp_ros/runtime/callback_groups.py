"""``rclpy.callback_groups``: which callbacks may run at the same time."""

from __future__ import annotations

import threading
import weakref

__all__ = ['CallbackGroup', 'MutuallyExclusiveCallbackGroup', 'ReentrantCallbackGroup']


class CallbackGroup:
    """Base class: a set of entities whose callbacks share a concurrency rule."""

    def __init__(self) -> None:
        self.entities: weakref.WeakSet = weakref.WeakSet()
        self._lock = threading.Lock()

    def add_entity(self, entity: object) -> None:
        self.entities.add(entity)

    def has_entity(self, entity: object) -> bool:
        return entity in self.entities

    def can_execute(self, entity: object) -> bool:
        return True

    def beginning_execution(self, entity: object) -> bool:
        return True

    def ending_execution(self, entity: object) -> None:
        pass


class ReentrantCallbackGroup(CallbackGroup):
    """Callbacks may run concurrently (in a MultiThreadedExecutor)."""


class MutuallyExclusiveCallbackGroup(CallbackGroup):
    """At most one callback of the group runs at a time (the default group of a node)."""

    def __init__(self) -> None:
        super().__init__()
        self._active: object | None = None

    def can_execute(self, entity: object) -> bool:
        return self._active is None

    def beginning_execution(self, entity: object) -> bool:
        with self._lock:
            if self._active is None:
                self._active = entity
                return True
            return False

    def ending_execution(self, entity: object) -> None:
        with self._lock:
            self._active = None
