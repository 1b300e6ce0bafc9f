"""The message type store used to describe, decode and check bag topics.

It is the client layer's store (:func:`mindgrasp_ros.typestore`): ROS 2 Jazzy common_interfaces,
the service types and ``mindgrasp_msgs`` registered from its own ``.msg``/``.srv`` files, so bags
and the wire always agree on definitions and hashes.
"""

from __future__ import annotations

from rosbags.typesys.store import Typestore

__all__ = ['typestore']


def typestore() -> Typestore:
    """The shared type store (built once per process)."""
    from mindgrasp_ros.typesupport import typestore as client_typestore

    return client_typestore()
