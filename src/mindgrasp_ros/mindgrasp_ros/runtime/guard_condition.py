"""``rclpy.guard_condition.GuardCondition``: runs its callback on the executor after
:meth:`~GuardCondition.trigger`."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.entity import Entity

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.node import Node

__all__ = ['GuardCondition']


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
