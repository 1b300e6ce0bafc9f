"""Graph introspection of a DDS-less (``transport='intra'``) context.

A lock-step run (:class:`mindgrasp_ros.graph.lockstep.LockstepRunner`) has no DDS participant, so
there is no discovery to ask; its whole graph is the nodes of the one context. This answers the
same queries as :class:`mindgrasp_ros.runtime.dds.discovery.GraphCache` from those nodes'
publishers, subscriptions, services and clients (their type names and QoS as created), so a node
that discovers topics (the bag recorder) works the same in lock-step as on DDS.
"""

from __future__ import annotations

from collections import defaultdict
from typing import TYPE_CHECKING

from mindgrasp_ros.runtime.endpoint_info import TopicEndpointInfo

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.context import Context

__all__ = ['IntraGraph']


def _service_type(type_name: str) -> str:
    """``pkg/srv/X_Request`` -> ``pkg/srv/X`` (as ``ros2 service list -t`` shows it)."""
    return type_name.removesuffix('_Request').removesuffix('_Response')


class IntraGraph:
    """The graph of one DDS-less context, read from its nodes on every query (no cache: the
    queries are cheap, and a lock-step step may create or destroy endpoints)."""

    def __init__(self, context: Context) -> None:
        self._context = context

    def close(self) -> None:
        """Nothing to free (the DDS graph closes its readers)."""

    def _nodes(self) -> list:
        return self._context.node_list()

    def node_names_and_namespaces(self) -> list[tuple[str, str]]:
        """``(name, namespace)`` of every node, sorted by namespace then name."""
        out = {(n.get_name(), n.get_namespace()) for n in self._nodes()}
        return sorted(out, key=lambda x: (x[1], x[0]))

    def topic_names_and_types(self) -> list[tuple[str, list[str]]]:
        """``(topic, [types])`` of every topic with a publisher or a subscription, sorted."""
        table: dict[str, set[str]] = defaultdict(set)
        for node in self._nodes():
            for entity in (*node.publishers, *node.subscriptions):
                table[entity.topic_name].add(entity.type_name)
        return sorted((k, sorted(v)) for k, v in table.items())

    def service_names_and_types(self) -> list[tuple[str, list[str]]]:
        """``(service, [types])`` of every service server or client, sorted."""
        table: dict[str, set[str]] = defaultdict(set)
        for node in self._nodes():
            for entity in (*node.services, *node.clients):
                table[entity.srv_name].add(_service_type(entity.request_type_name))
        return sorted((k, sorted(v)) for k, v in table.items())

    def endpoints(self, topic: str, kind: str) -> list[TopicEndpointInfo]:
        """Publishers (``kind='publisher'``) or subscriptions of ``topic`` (a resolved name)."""
        out = []
        for node in self._nodes():
            entities = node.publishers if kind == 'publisher' else node.subscriptions
            for e in entities:
                if e.topic_name != topic:
                    continue
                out.append(TopicEndpointInfo(
                    node_name=node.get_name(), node_namespace=node.get_namespace(),
                    topic_type=e.type_name,
                    endpoint_type='PUBLISHER' if kind == 'publisher' else 'SUBSCRIPTION',
                    endpoint_gid=e.gid, qos_profile=e.qos_profile))
        return sorted(out, key=lambda e: (e.node_namespace, e.node_name, e.endpoint_gid))

    def node_endpoints(self, name: str, namespace: str) -> dict[str, list[tuple[str, str]]]:
        """Topics and services of a node: ``{'publishers': [(topic, type)], 'subscribers': ...,
        'services': ..., 'clients': ...}``."""
        out: dict[str, set[tuple[str, str]]] = defaultdict(set)
        for node in self._nodes():
            if node.get_name() != name or node.get_namespace() != namespace:
                continue
            out['publishers'] |= {(p.topic_name, p.type_name) for p in node.publishers}
            out['subscribers'] |= {(s.topic_name, s.type_name) for s in node.subscriptions}
            out['services'] |= {(s.srv_name, _service_type(s.request_type_name))
                                for s in node.services}
            out['clients'] |= {(c.srv_name, _service_type(c.request_type_name))
                               for c in node.clients}
        return {k: sorted(v) for k, v in out.items() if v}
