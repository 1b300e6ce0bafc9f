"""The runtime's DDS layer: the only modules that import ``cyclonedds``.

* :mod:`.participant`: the process's participant, readers and writers, names and QoS the way
  rmw_cyclonedds_cpp maps them.
* :mod:`.discovery`: graph queries (nodes, endpoints) from the built-in topics and
  ``ros_discovery_info``.
* :mod:`.waitset`: an executor's wait set over its readers.

A DDS-less context (lock-step) imports none of them.
"""

from __future__ import annotations

from mindgrasp_ros.runtime.dds.participant import (
    DdsError,
    DdsParticipant,
    DdsReader,
    DdsWriter,
    dds_type_name,
    ros_type_name_from_dds,
)

__all__ = ['DdsError', 'DdsParticipant', 'DdsReader', 'DdsWriter', 'dds_type_name',
           'ros_type_name_from_dds']
