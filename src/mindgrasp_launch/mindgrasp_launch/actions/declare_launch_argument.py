"""``DeclareLaunchArgument``: a ``name:=value`` argument of a launch description."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.substitutions import (
    SomeSubstitutions,
    TextSubstitution,
    normalize,
    perform_substitutions,
)

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext


class DeclareLaunchArgument(Action):
    """Declare a launch argument with an optional default, description and allowed values.

    Without a default the argument is required. The value given on the command line
    (``name:=value``) or by an including description wins over the default.
    """

    def __init__(self, name: str, *, default_value: SomeSubstitutions | None = None,
                 description: str = 'no description given',
                 choices: Sequence[str] | None = None, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        if not name or ':=' in name or ' ' in name:
            msg = f'launch argument name {name!r} is invalid: use letters, digits and underscores.'
            raise LaunchError(msg)
        self.name = name
        self.default_value = None if default_value is None else normalize(default_value)
        self.description = description
        self.choices = None if choices is None else [str(c) for c in choices]
        if (self.choices is not None and isinstance(default_value, str)
                and default_value not in self.choices):
            msg = (f"launch argument '{name}': default {default_value!r} is not one of its "
                   f"choices {self.choices}; change the default or the choices.")
            raise LaunchError(msg)

    def default_text(self, context: LaunchContext | None = None) -> str | None:
        """The default as text (substitutions resolved when a context is given)."""
        if self.default_value is None:
            return None
        if context is None:
            return ''.join(s.text if isinstance(s, TextSubstitution) else s.describe()
                           for s in self.default_value)
        return perform_substitutions(context, self.default_value)

    def execute(self, context: LaunchContext) -> None:
        context.declared_arguments.setdefault(self.name, self)
        if self.name not in context.launch_configurations:
            if self.default_value is None:
                msg = (f"launch argument '{self.name}' is required and was not given: add "
                       f"{self.name}:=<value> ({self.description}).")
                raise LaunchError(msg)
            context.launch_configurations[self.name] = perform_substitutions(
                context, self.default_value)
        value = context.launch_configurations[self.name]
        if self.choices is not None and value not in self.choices:
            msg = (f"launch argument '{self.name}' got {value!r}, which is not one of its "
                   f"choices: {', '.join(self.choices)}. Give one of them.")
            raise LaunchError(msg)
