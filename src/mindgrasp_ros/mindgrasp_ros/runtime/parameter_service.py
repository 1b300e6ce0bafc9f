"""The six parameter services every rclpy node offers (``~/get_parameters`` ...)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime.exceptions import ParameterNotDeclaredException
from mindgrasp_ros.runtime.parameter import Parameter
from mindgrasp_ros.runtime.qos import qos_profile_parameters
from mindgrasp_ros.typesupport import get_message_class, get_service_class

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.node import Node

__all__ = ['ParameterService']


def _srv(name: str) -> type:
    return get_service_class(f'rcl_interfaces/srv/{name}')


class ParameterService:
    """Serves rcl_interfaces parameter services for one node."""

    def __init__(self, node: Node) -> None:
        self._node = node
        fqn = node.get_fully_qualified_name()
        for name, handler in (
                ('describe_parameters', self._describe),
                ('get_parameters', self._get),
                ('get_parameter_types', self._get_types),
                ('list_parameters', self._list),
                ('set_parameters', self._set),
                ('set_parameters_atomically', self._set_atomically)):
            srv_type = ''.join(part.capitalize() for part in name.split('_'))
            node.create_service(_srv(srv_type), f'{fqn}/{name}', handler,
                                qos_profile=qos_profile_parameters)

    def _get(self, request: Any, response: Any) -> Any:
        values = []
        for name in request.names:
            param = self._node.get_parameter_or(name)
            values.append(param.get_parameter_value())
        response.values = values
        return response

    def _get_types(self, request: Any, response: Any) -> Any:
        response.types = [int(self._node.get_parameter_or(n).type_) for n in request.names]
        return response

    def _describe(self, request: Any, response: Any) -> Any:
        out = []
        for name in request.names:
            try:
                out.append(self._node.describe_parameter(name))
            except ParameterNotDeclaredException:
                out.append(get_message_class('rcl_interfaces/msg/ParameterDescriptor')(name=name))
        response.descriptors = out
        return response

    def _list(self, request: Any, response: Any) -> Any:
        names = sorted(self._node.get_parameters_by_prefix(''))
        prefixes = list(request.prefixes)
        depth = int(request.depth)
        selected = []
        for name in names:
            if prefixes and not any(name == p or name.startswith(p + '.') for p in prefixes):
                continue
            if depth:
                rel = name
                for p in prefixes:
                    if name.startswith(p + '.'):
                        rel = name[len(p) + 1:]
                if rel.count('.') >= depth:
                    continue
            selected.append(name)
        result = get_message_class('rcl_interfaces/msg/ListParametersResult')(
            names=selected,
            prefixes=sorted({n.rsplit('.', 1)[0] for n in selected if '.' in n}))
        response.result = result
        return response

    def _set(self, request: Any, response: Any) -> Any:
        params = [Parameter.from_parameter_msg(p) for p in request.parameters]
        response.results = self._node.set_parameters(params)
        return response

    def _set_atomically(self, request: Any, response: Any) -> Any:
        params = [Parameter.from_parameter_msg(p) for p in request.parameters]
        response.result = self._node.set_parameters_atomically(params)
        return response
