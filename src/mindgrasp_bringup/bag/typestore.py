"""The message type store used to describe, decode and check bag topics.

Prefers ``mindgrasp_ros.typestore()`` (ROS 2 Jazzy types + ``mindgrasp_msgs`` + service types, the
same store the client layer publishes with). Until that exists, builds an equivalent store from
rosbags' Jazzy store and the ``.msg``/``.srv`` files of ``mindgrasp_msgs``.
"""

from __future__ import annotations

import functools
from pathlib import Path

from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

__all__ = ['custom_types', 'typestore']


def custom_types() -> dict:
    """Parse ``mindgrasp_msgs`` messages and services into rosbags field definitions.

    Services become ``<Name>_Request`` and ``<Name>_Response`` message types, as rosidl names them.
    """
    import mindgrasp_msgs

    root = Path(mindgrasp_msgs.__file__).parent
    types: dict = {}
    for path in sorted((root / 'msg').glob('*.msg')):
        types.update(get_types_from_msg(path.read_text(), f'mindgrasp_msgs/msg/{path.stem}'))
    for path in sorted((root / 'srv').glob('*.srv')):
        request, _, response = path.read_text().partition('\n---')
        for part, suffix in ((request, 'Request'), (response, 'Response')):
            parsed = get_types_from_msg(part, f'mindgrasp_msgs/srv/{path.stem}_{suffix}')
            # rosbags files every parsed type under <pkg>/<kind>/msg/; services live in <pkg>/srv/.
            types.update({name.replace('/srv/msg/', '/srv/'): fields
                          for name, fields in parsed.items()})
    return types


@functools.lru_cache(maxsize=1)
def typestore() -> Typestore:
    """The shared type store: Jazzy standard types plus ``mindgrasp_msgs`` (cached)."""
    try:
        import mindgrasp_ros

        store = getattr(mindgrasp_ros, 'typestore', None)
        if callable(store):
            return store()
    except Exception:  # the client layer is optional here; fall back below
        pass
    store = get_typestore(Stores.ROS2_JAZZY)
    # One register() call: rosbags resolves references between the new types (Detection inside
    # DetectionArray) within the batch, so the order of the files does not matter.
    store.register(custom_types())
    return store
