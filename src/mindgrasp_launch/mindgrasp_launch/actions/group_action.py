"""``GroupAction`` and ``PushRosNamespace``."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.substitutions import SomeSubstitutions, perform_substitutions

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext


def join_namespace(base: str, namespace: str) -> str:
    """ROS namespace joining: an absolute ``namespace`` replaces ``base``; '' keeps it."""
    namespace = namespace.strip()
    if not namespace:
        return base
    joined = namespace if namespace.startswith('/') else base.rstrip('/') + '/' + namespace
    joined = '/' + '/'.join(p for p in joined.split('/') if p)
    return '' if joined == '/' else joined


class GroupAction(Action):
    """Run actions together under one condition; ``scoped=True`` keeps configurations and
    namespaces set inside from leaking out."""

    def __init__(self, actions: Iterable[object], *, scoped: bool = True,
                 launch_configurations: dict[str, SomeSubstitutions] | None = None,
                 **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.actions = list(actions)
        self.scoped = scoped
        self.launch_configurations = dict(launch_configurations or {})

    def children(self) -> list[Action]:
        return [a for a in self.actions if isinstance(a, Action)]

    def execute(self, context: LaunchContext) -> None:
        from mindgrasp_launch.description import visit_entities

        inner = context.scoped() if self.scoped else context
        for name, value in self.launch_configurations.items():
            inner.launch_configurations[name] = perform_substitutions(context, value)
        visit_entities(self.actions, inner)


class PushRosNamespace(Action):
    """Prefix the namespace of the nodes that follow (inside the enclosing group)."""

    def __init__(self, namespace: SomeSubstitutions, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.namespace = namespace

    def execute(self, context: LaunchContext) -> None:
        ns = perform_substitutions(context, self.namespace)
        if any(c in ns for c in ' :~{}'):
            msg = f'PushRosNamespace: {ns!r} is not a valid ROS namespace; use letters, / and _.'
            raise LaunchError(msg)
        context.ros_namespace = join_namespace(context.ros_namespace, ns)
