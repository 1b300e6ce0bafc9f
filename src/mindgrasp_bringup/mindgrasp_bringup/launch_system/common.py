"""Pieces several launch profiles share, built through :mod:`mindgrasp_bringup.launch_api`: real
launch_ros actions under ``ros2 launch``, ours under ``mindgrasp launch``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mindgrasp_bringup import launch_api as la


def classifier_nodes(files: list[Path], model_argument: str = 'model') -> list[Any]:
    """The classifier node (name ``classifier``), with ``model:=<file>`` when that launch argument
    is not empty, else the model of its parameter files. Declare the argument in the profile."""
    return [
        la.Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                parameters=list(files),
                condition=la.LaunchConfigurationEquals(model_argument, '')),
        la.Node(package='mindgrasp_classifier', executable='classifier_node', name='classifier',
                parameters=[*files, {'model': la.LaunchConfiguration(model_argument)}],
                condition=la.LaunchConfigurationNotEquals(model_argument, '')),
    ]


def eeg_source_arguments() -> list[Any]:
    """``amp:=virtual|lsl`` and ``eeg_stream:=NAME``, for :func:`eeg_source_nodes`."""
    return [
        la.DeclareLaunchArgument('amp', default_value='virtual', choices=['virtual', 'lsl'],
                                 description='EEG source: virtual (virtual amplifier + virtual '
                                             'subject) or lsl (a real amplifier streaming over '
                                             'LSL)'),
        la.DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                                 description='LSL stream name of the amplifier'),
    ]


def eeg_source_nodes(files: list[Path], seed: object, subject_mode: object) -> list[Any]:
    """The virtual amplifier (only with ``amp:=virtual``) and the acquisition node on
    ``eeg_stream``; declare :func:`eeg_source_arguments` in the profile."""
    stream = la.LaunchConfiguration('eeg_stream')
    return [
        la.Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
                parameters=[*files, {'stream_name': stream, 'seed': seed,
                                     'subject_mode': subject_mode}],
                condition=la.LaunchConfigurationEquals('amp', 'virtual')),
        la.Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
                parameters=[*files, {'stream_name': stream}]),
    ]
