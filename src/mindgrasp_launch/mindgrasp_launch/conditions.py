"""Conditions: whether an action runs, decided when the description is resolved."""

from __future__ import annotations

from typing import TYPE_CHECKING

from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.substitutions import SomeSubstitutions, perform_substitutions

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext

_TRUE = ('true', '1', 'yes', 'on')
_FALSE = ('false', '0', 'no', 'off')


def evaluate_bool(text: str, what: str) -> bool:
    """Parse a launch boolean ('true'/'false', '1'/'0', 'yes'/'no', 'on'/'off')."""
    value = text.strip().lower()
    if value in _TRUE:
        return True
    if value in _FALSE:
        return False
    msg = f"{what} expects true or false, got {text!r}: give true or false."
    raise LaunchError(msg)


class Condition:
    """Base class: ``evaluate(context) -> bool``."""

    def evaluate(self, context: LaunchContext) -> bool:  # pragma: no cover - abstract
        raise NotImplementedError


class IfCondition(Condition):
    """True when the expression resolves to true."""

    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        self.predicate_expression = predicate_expression

    def evaluate(self, context: LaunchContext) -> bool:
        return evaluate_bool(perform_substitutions(context, self.predicate_expression),
                             'IfCondition')


class UnlessCondition(Condition):
    """True when the expression resolves to false."""

    def __init__(self, predicate_expression: SomeSubstitutions) -> None:
        self.predicate_expression = predicate_expression

    def evaluate(self, context: LaunchContext) -> bool:
        return not evaluate_bool(perform_substitutions(context, self.predicate_expression),
                                 'UnlessCondition')


class LaunchConfigurationEquals(Condition):
    """True when a launch configuration equals ``expected_value`` (text comparison)."""

    def __init__(self, launch_configuration_name: str, expected_value: SomeSubstitutions) -> None:
        self.name = launch_configuration_name
        self.expected_value = expected_value

    def evaluate(self, context: LaunchContext) -> bool:
        from mindgrasp_launch.substitutions import LaunchConfiguration

        return (LaunchConfiguration(self.name).perform(context)
                == perform_substitutions(context, self.expected_value))


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    """True when a launch configuration differs from ``expected_value``."""

    def evaluate(self, context: LaunchContext) -> bool:
        return not super().evaluate(context)
