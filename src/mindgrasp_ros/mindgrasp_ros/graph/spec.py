"""A node of a graph as data: module, name, parameters, remaps (as launch_ros' ``Node`` action).

Every graph host takes the same spec (:mod:`mindgrasp_ros.graph.host`): the launch's nodes
resolved by the launcher (``lockstep_components``), the ``--composed`` container's plan, the
experiment engine's trial graph and the replayed nodes::

    spec = NodeSpec('listener', 'my_pkg.listener_node', parameters={'min_certainty': 0.6},
                    remaps={'/eeg/raw': '/eeg/filtered'})
    spec.with_parameters({'seed': 7})      # a copy with more parameters (later ones win)

A host that builds the node in its own process passes what the spec says as rclpy's ``Node``
takes it (:meth:`NodeSpec.node_arguments`: ``cli_args`` and typed ``parameter_overrides``), so
the same node class runs composed under our runtime and under the real rclpy. Parameters stay
typed (a dict, never ``-p name:=value`` text) until a host starts the node in a process of its
own, which writes them to a parameter file (:meth:`NodeSpec.process_arguments`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_ros.graph.loader import load_node_class
from mindgrasp_ros.node_traits import NodeTraits, traits_of

__all__ = ['NodeSpec']


@dataclass
class NodeSpec:
    """One node of a graph.

    Attributes
    ----------
    label : str
        What the graph calls the node (the launch's label; the name of its parameter file, of
        ``--param LABEL.NAME=V`` and of its log).
    module : str
        ``pkg.mod`` (the one Node subclass it defines) or ``pkg.mod:Class``.
    name : str
        Node name given to the node (``-r __node:=name``); '' keeps the class's own.
    parameters : dict of str to object
        Parameter values (dotted names), set after the node's parameter files and ``-p``
        arguments, so they win (rclpy's ``parameter_overrides``).
    remaps : dict of str to str
        Topic and service remappings, from -> to.
    ros_args : list of str
        Further ROS arguments as text (``--params-file F``, ``--log-level L``, ``-r __ns:=/ns``),
        before :attr:`parameters`.
    """

    label: str
    module: str
    name: str = ''
    parameters: dict[str, Any] = field(default_factory=dict)
    remaps: dict[str, str] = field(default_factory=dict)
    ros_args: list[str] = field(default_factory=list)

    def node_class(self) -> type:
        """The Node subclass of :attr:`module` (:class:`CompositionError` when there is none)."""
        return load_node_class(self.module)

    @property
    def traits(self) -> NodeTraits:
        """What the node class declares for the graph hosts (:class:`NodeTraits`)."""
        return traits_of(self.node_class())

    def with_parameters(self, parameters: Mapping[str, Any]) -> NodeSpec:
        """A copy with ``parameters`` set on top of this spec's."""
        return dataclasses.replace(self, parameters={**self.parameters, **parameters},
                                   remaps=dict(self.remaps), ros_args=list(self.ros_args))

    def ros_arguments(self) -> list[str]:
        """``--ros-args`` for a node built in this process (rclpy's ``cli_args``): name,
        remaps and :attr:`ros_args` (the parameters are passed typed, :meth:`node_arguments`)."""
        args = ['--ros-args', *[a for a in self.ros_args if a != '--ros-args']]
        if self.name:
            args += ['-r', f'__node:={self.name}']
        for src, dst in self.remaps.items():
            args += ['-r', f'{src}:={dst}']
        return args

    def node_arguments(self, parameter_class: type,
                       parameters: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The keyword arguments that build this node in this process, as rclpy's ``Node``
        takes them.

        Parameters
        ----------
        parameter_class : type
            The ``Parameter`` class of the rclpy in use (``rclpy.parameter.Parameter``).
        parameters : mapping of str to object, optional
            Parameter values set on top of :attr:`parameters` (later ones win).

        Returns
        -------
        dict
            ``cli_args`` (:meth:`ros_arguments`) and ``parameter_overrides`` (one
            ``parameter_class(name, value=value)`` per parameter, typed from its value).
        """
        values = {**self.parameters, **(parameters or {})}
        return {'cli_args': self.ros_arguments(),
                'parameter_overrides': [parameter_class(name, value=value)
                                        for name, value in values.items()]}

    def process_arguments(self, params_dir: Path) -> list[str]:
        """``--ros-args`` for the node in a process of its own: :meth:`ros_arguments` and
        :attr:`parameters` written to ``params_dir/<label>.yaml`` (a ROS 2 parameter file)."""
        import yaml

        args = self.ros_arguments()
        if self.parameters:
            path = Path(params_dir) / f'{self.label}.yaml'
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(yaml.safe_dump({'/**': {'ros__parameters': self.parameters}},
                                           sort_keys=True), encoding='utf-8')
            args += ['--params-file', str(path)]
        return args
