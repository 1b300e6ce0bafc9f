"""``SetLaunchConfiguration`` and ``LogInfo``: small actions on the context."""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.substitutions import SomeSubstitutions, perform_substitutions

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext

logger = logging.getLogger('launch')


class SetLaunchConfiguration(Action):
    """Set a launch configuration for the actions that follow (in the current scope)."""

    def __init__(self, name: str, value: SomeSubstitutions, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.name = name
        self.value = value

    def execute(self, context: LaunchContext) -> None:
        context.launch_configurations[self.name] = perform_substitutions(context, self.value)


class LogInfo(Action):
    """Log a message when the description is resolved."""

    def __init__(self, *, msg: SomeSubstitutions, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.msg = msg

    def execute(self, context: LaunchContext) -> None:
        logger.info('%s', perform_substitutions(context, self.msg))


class SetParameter(Action):
    """Give every node that follows (in the current scope) this parameter, as
    ``launch_ros.actions.SetParameter``; a node's own parameters win."""

    def __init__(self, name: str, value: object, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.name = name
        self.value = value

    def execute(self, context: LaunchContext) -> None:
        from mindgrasp_launch.substitutions import resolve_parameter_value

        context.global_parameters[self.name] = resolve_parameter_value(context, self.value)


class SetRemap(Action):
    """Remap a topic or service for every node that follows (in the current scope)."""

    def __init__(self, src: SomeSubstitutions, dst: SomeSubstitutions, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.src = src
        self.dst = dst

    def execute(self, context: LaunchContext) -> None:
        context.global_remappings.append((perform_substitutions(context, self.src),
                                          perform_substitutions(context, self.dst)))


class Shutdown(Action):
    """Used as ``on_exit=Shutdown()`` of a process: its exit ends the whole launch."""

    def __init__(self, *, reason: str = 'a process with on_exit=Shutdown() ended',
                 **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.reason = reason

    def execute(self, context: LaunchContext) -> None:
        msg = 'Shutdown() is only supported as on_exit=Shutdown() of a Node or ExecuteProcess.'
        from mindgrasp_launch.errors import LaunchError

        raise LaunchError(msg)
