"""The state a launch description is resolved in: launch configurations and the ROS namespace."""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mindgrasp_launch.actions.declare_launch_argument import (
        DeclareLaunchArgument,
    )
    from mindgrasp_launch.actions.execute_process import ProcessSpec


@dataclass
class LaunchContext:
    """What resolving a launch description reads and fills.

    ``launch_configurations`` maps argument names to string values (as ``ros2 launch``: every
    value is text until a node parameter parses it as YAML). ``processes`` collects what the
    description asks to start, in order.
    """

    launch_configurations: dict[str, str] = field(default_factory=dict)
    ros_namespace: str = ''
    launch_file: Path | None = None
    processes: list[ProcessSpec] = field(default_factory=list)
    declared_arguments: dict[str, DeclareLaunchArgument] = field(default_factory=dict)
    #: names of the launch files being resolved, outermost first (include cycles are errors)
    include_stack: list[str] = field(default_factory=list)
    #: set by SetParameter / SetRemap for the nodes that follow (in the current scope)
    global_parameters: dict[str, Any] = field(default_factory=dict)
    global_remappings: list[tuple[str, str]] = field(default_factory=list)

    def scoped(self) -> LaunchContext:
        """A child context: configurations and namespace changed inside do not leak out."""
        child = copy.copy(self)
        child.launch_configurations = dict(self.launch_configurations)
        child.include_stack = list(self.include_stack)
        child.global_parameters = dict(self.global_parameters)
        child.global_remappings = list(self.global_remappings)
        return child
