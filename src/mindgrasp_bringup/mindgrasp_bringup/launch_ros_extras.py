"""Our launch extensions as real ``launch`` entities, for launch files run by ``ros2 launch``.

Imported only through :mod:`mindgrasp_bringup.launch_api` when the real ``launch`` is in use.
"""

from __future__ import annotations

from launch.launch_context import LaunchContext
from launch.some_substitutions_type import SomeSubstitutionsType
from launch.substitution import Substitution
from launch.substitutions.substitution_failure import SubstitutionFailure
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions


class CameraSpec(Substitution):
    """One field (``'width'``, ``'height'`` or ``'rate'``) of a ``WIDTHxHEIGHT@HZ`` text: parsed
    by :func:`mindgrasp_bringup.launch_args.parse_camera`, never evaluated."""

    def __init__(self, value: SomeSubstitutionsType, field: str) -> None:
        super().__init__()
        self.value = normalize_to_list_of_substitutions(value)
        self.field = field

    def describe(self) -> str:
        return f'CameraSpec({" + ".join(s.describe() for s in self.value)}, {self.field!r})'

    def perform(self, context: LaunchContext) -> str:
        from mindgrasp_bringup.launch_args import CAMERA_FIELDS, parse_camera

        try:
            values = parse_camera(perform_substitutions(context, self.value))
        except ValueError as exc:
            raise SubstitutionFailure(str(exc)) from None
        return str(values[CAMERA_FIELDS.index(self.field)])


class SplitArguments(Substitution):
    """``arguments=[SplitArguments(LaunchConfiguration('driver_args'))]``.

    ``launch`` passes each item of ``arguments`` as one argument, so under ``ros2 launch`` this
    substitution holds at most one argument; several need ``mindgrasp launch`` (which splits them
    with shell quoting) or the driver's own launch file.
    """

    def __init__(self, value: SomeSubstitutionsType) -> None:
        super().__init__()
        self.value = normalize_to_list_of_substitutions(value)

    def describe(self) -> str:
        return f'SplitArguments({" + ".join(s.describe() for s in self.value)})'

    def perform(self, context: LaunchContext) -> str:
        text = perform_substitutions(context, self.value)
        if len(text.split()) > 1:
            msg = (f'{text!r} holds several arguments, which ros2 launch passes as one: run this '
                   f'profile with mindgrasp launch, or start the driver with its own launch file.')
            raise SubstitutionFailure(msg)
        return text.strip()
