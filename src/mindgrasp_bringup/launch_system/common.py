"""Pieces several launch profiles share."""

from __future__ import annotations

from pathlib import Path

from mindgrasp_bringup.launch_system.actions.node import Node
from mindgrasp_bringup.launch_system.conditions import (
    LaunchConfigurationEquals,
    LaunchConfigurationNotEquals,
)
from mindgrasp_bringup.launch_system.substitutions import LaunchConfiguration


def classifier_nodes(files: list[Path], model_argument: str = 'model') -> list[Node]:
    """The classifier node (name ``classifier``), with ``model:=<file>`` when that launch argument
    is not empty, else the model of its parameter files. Declare the argument in the profile."""
    return [
        Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
             parameters=list(files), condition=LaunchConfigurationEquals(model_argument, '')),
        Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
             parameters=[*files, {'model': LaunchConfiguration(model_argument)}],
             condition=LaunchConfigurationNotEquals(model_argument, '')),
    ]
