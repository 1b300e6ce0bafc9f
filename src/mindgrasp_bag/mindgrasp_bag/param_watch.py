"""The recorder's ROS side of :class:`~mindgrasp_bag.param_changes.ParameterChangeLog`:
decodes the recorded ``/parameter_events`` and reads each new node's parameters once (its
``list_parameters`` / ``get_parameters`` services), so that each change has its old value."""

from __future__ import annotations

from typing import Any

from mindgrasp_bag.param_changes import EVENT_TYPE, ParameterChangeLog


def _values(params: Any) -> dict[str, Any]:
    """``rcl_interfaces/Parameter[]`` -> ``{name: Python value}``."""
    from mindgrasp_ros.runtime.parameter import parameter_value_to_python

    return {p.name: parameter_value_to_python(p.value) for p in params}


class ParameterWatch:
    """Feeds a change log from a node (the recorder): :meth:`event` with each raw
    ``/parameter_events`` message, :meth:`poll` now and then to read the values of new nodes.

    Parameters
    ----------
    node
        The node whose clients read the parameters.
    log
        Where the changes go.
    """

    def __init__(self, node: Any, log: ParameterChangeLog) -> None:
        self.node = node
        self.log = log
        self._seen: set[str] = {node.get_fully_qualified_name()}
        self._clients: dict[str, tuple[Any, Any]] = {}   # node -> (list client, get client)
        self._finished: list[Any] = []   # clients to destroy (not inside their own callback)

    def event(self, data: bytes, time_ns: int) -> None:
        """One recorded ``/parameter_events`` message (CDR) received at ``time_ns``."""
        from mindgrasp_ros.typesupport import deserialize

        msg = deserialize(data, EVENT_TYPE)
        stamp = int(msg.stamp.sec) * 1_000_000_000 + int(msg.stamp.nanosec)
        self.log.event(time_ns, stamp, msg.node, _values(msg.new_parameters),
                       _values(msg.changed_parameters), [p.name for p in msg.deleted_parameters])

    def poll(self) -> None:
        """Ask every node not seen before for its parameters (the answer seeds the log)."""
        from mindgrasp_ros.interfaces.rcl_interfaces.srv import GetParameters, ListParameters

        while self._finished:
            self.node.destroy_client(self._finished.pop())
        for name, namespace in self.node.get_node_names_and_namespaces():
            fqn = f'{namespace.rstrip("/")}/{name}'
            if fqn in self._seen or name.startswith('_'):   # hidden: CLI tools
                continue
            self._seen.add(fqn)
            self._clients[fqn] = (self.node.create_client(ListParameters, f'{fqn}/list_parameters'),
                                  self.node.create_client(GetParameters, f'{fqn}/get_parameters'))
        for fqn, (list_client, get_client) in list(self._clients.items()):
            if list_client.service_is_ready() and get_client.service_is_ready():
                del self._clients[fqn]
                self._read(fqn, list_client, get_client)

    def _read(self, fqn: str, list_client: Any, get_client: Any) -> None:
        def got_names(future: Any) -> None:
            names = list(future.result().result.names) if future.result() is not None else []
            request = get_client.srv_type.Request(names=names)
            get_client.call_async(request).add_done_callback(
                lambda f: got_values(names, f))

        def got_values(names: list[str], future: Any) -> None:
            from mindgrasp_ros.runtime.parameter import parameter_value_to_python

            if future.result() is not None:
                self.log.seed(fqn, {n: parameter_value_to_python(v)
                                    for n, v in zip(names, future.result().values, strict=False)})
            self._finished += [list_client, get_client]

        list_client.call_async(list_client.srv_type.Request()).add_done_callback(got_names)
