"""Pieces several launch profiles share."""

from __future__ import annotations

from pathlib import Path

from mindgrasp_bringup.launch_system.actions.declare_launch_argument import DeclareLaunchArgument
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


def eeg_source_arguments() -> list[DeclareLaunchArgument]:
    """``amp:=virtual|lsl`` and ``eeg_stream:=NAME``, for :func:`eeg_source_nodes`."""
    return [
        DeclareLaunchArgument('amp', default_value='virtual', choices=['virtual', 'lsl'],
                              description='EEG source: virtual (virtual amplifier + virtual '
                                          'subject) or lsl (a real amplifier streaming over LSL)'),
        DeclareLaunchArgument('eeg_stream', default_value='MIndGrasp-VirtualAmp',
                              description='LSL stream name of the amplifier'),
    ]


def eeg_source_nodes(files: list[Path], seed: object, subject_mode: object) -> list[Node]:
    """The virtual amplifier (only with ``amp:=virtual``) and the acquisition node on
    ``eeg_stream``; declare :func:`eeg_source_arguments` in the profile."""
    stream = LaunchConfiguration('eeg_stream')
    return [
        Node(package='mindgrasp_eeg', executable='virtual_amp_node', name='virtual_amp',
             parameters=[*files, {'stream_name': stream, 'seed': seed,
                                  'subject_mode': subject_mode}],
             condition=LaunchConfigurationEquals('amp', 'virtual')),
        Node(package='mindgrasp_eeg', executable='acquisition_node', name='eeg_acquisition',
             parameters=[*files, {'stream_name': stream}]),
    ]
