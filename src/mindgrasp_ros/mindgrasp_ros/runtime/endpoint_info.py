"""``TopicEndpointInfo``: one endpoint of a topic, as graph queries return it (DDS or
in-process)."""

from __future__ import annotations

from dataclasses import dataclass

from mindgrasp_ros.runtime.qos import QoSProfile

__all__ = ['TopicEndpointInfo']


@dataclass
class TopicEndpointInfo:
    """One publisher or subscription of a topic (``rclpy.topic_endpoint_info``)."""

    node_name: str
    node_namespace: str
    topic_type: str
    endpoint_type: str  # 'PUBLISHER' | 'SUBSCRIPTION'
    endpoint_gid: bytes
    qos_profile: QoSProfile
    topic_type_hash: str = ''
