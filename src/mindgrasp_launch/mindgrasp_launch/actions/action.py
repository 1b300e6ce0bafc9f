"""Base class of launch actions."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from mindgrasp_launch.conditions import Condition
    from mindgrasp_launch.context import LaunchContext


class Action:
    """Something a launch description does when it is resolved.

    Subclasses implement :meth:`execute`; :meth:`visit` checks the condition first, as
    ``launch.Action`` does.
    """

    def __init__(self, *, condition: Condition | None = None) -> None:
        self.condition = condition

    def visit(self, context: LaunchContext) -> None:
        """Execute the action in ``context`` unless its condition is false."""
        if self.condition is not None and not self.condition.evaluate(context):
            return
        self.execute(context)

    def execute(self, context: LaunchContext) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def children(self) -> list[Action]:
        """Actions nested in this one (for listing arguments without resolving)."""
        return []
