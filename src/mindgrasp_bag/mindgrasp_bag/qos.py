"""Offered QoS profiles in the form rosbag2 (Jazzy, metadata version 9) stores them.

A profile is a dict ``{history: 'keep_last', depth: 10, reliability: 'reliable', durability:
'volatile', deadline: {sec, nsec}, lifespan: {sec, nsec}, liveliness: 'automatic',
liveliness_lease_duration: {sec, nsec}, avoid_ros_namespace_conventions: False}``. metadata.yaml
holds the list itself; MCAP channel metadata holds the same list as a YAML string.
(``rosbags.rosbag2.metadata.dump_qos_v9`` produces the same dicts but only from rosbags ``Qos``
tuples; the recorder gets rclpy ``QoSProfile`` objects from the graph, hence these helpers.)
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import yaml

__all__ = ['adapted_qos', 'compatible', 'dump_offered_qos', 'parse_offered_qos', 'qos_to_dict',
           'resubscribe_qos']

# Integer values used by metadata version <= 8 (rmw enums), mapped to the v9 names.
_HISTORY = {0: 'system_default', 1: 'keep_last', 2: 'keep_all', 3: 'unknown'}
_RELIABILITY = {0: 'system_default', 1: 'reliable', 2: 'best_effort', 3: 'unknown',
                4: 'best_available'}
_DURABILITY = {0: 'system_default', 1: 'transient_local', 2: 'volatile', 3: 'unknown',
               4: 'best_available'}
_LIVELINESS = {0: 'system_default', 1: 'automatic', 3: 'manual_by_topic', 4: 'unknown',
               5: 'best_available'}
_ENUMS = {'history': _HISTORY, 'reliability': _RELIABILITY, 'durability': _DURABILITY,
          'liveliness': _LIVELINESS}
_TIMES = ('deadline', 'lifespan', 'liveliness_lease_duration')


def _enum_name(value: Any, table: dict[int, str]) -> str:
    if isinstance(value, str):
        return value.lower()
    name = getattr(value, 'name', None)  # rclpy / our layer: IntEnum members
    if isinstance(name, str):
        return name.lower()
    return table.get(int(value), 'unknown')


def _time(value: Any) -> dict[str, int]:
    if value is None:
        return {'sec': 0, 'nsec': 0}
    if isinstance(value, dict):
        return {'sec': int(value.get('sec', 0)), 'nsec': int(value.get('nsec', 0))}
    nanoseconds = getattr(value, 'nanoseconds', None)  # rclpy Duration
    if nanoseconds is None:
        nanoseconds = int(float(value) * 1e9)  # seconds
    sec, nsec = divmod(int(nanoseconds), 1_000_000_000)
    return {'sec': sec, 'nsec': nsec}


def qos_to_dict(profile: Any) -> dict[str, Any]:
    """One QoS profile (rclpy ``QoSProfile``, rosbags ``Qos`` or dict) as a rosbag2 v9 dict."""
    def get(name: str, default: Any = None) -> Any:
        if isinstance(profile, dict):
            return profile.get(name, default)
        return getattr(profile, name, default)

    out: dict[str, Any] = {
        'history': _enum_name(get('history', 1), _HISTORY),
        'depth': int(get('depth', 0) or 0),
        'reliability': _enum_name(get('reliability', 1), _RELIABILITY),
        'durability': _enum_name(get('durability', 2), _DURABILITY),
    }
    for name in _TIMES[:2]:
        out[name] = _time(get(name))
    out['liveliness'] = _enum_name(get('liveliness', 1), _LIVELINESS)
    out['liveliness_lease_duration'] = _time(get('liveliness_lease_duration'))
    out['avoid_ros_namespace_conventions'] = bool(get('avoid_ros_namespace_conventions', False))
    return out


def dump_offered_qos(profiles: Iterable[Any]) -> str:
    """The YAML string rosbag2 stores in MCAP channel metadata ('' for no profiles)."""
    dicts = [qos_to_dict(p) for p in profiles]
    if not dicts:
        return ''
    return yaml.safe_dump(dicts, default_flow_style=False, sort_keys=False).strip()


def parse_offered_qos(value: str | Sequence[Any] | None) -> list[dict[str, Any]]:
    """Profiles from metadata.yaml (a list, v9) or a YAML string (MCAP metadata, v<=8)."""
    if not value:
        return []
    items = yaml.safe_load(value) if isinstance(value, str) else value
    if not isinstance(items, list):
        return []
    return [qos_to_dict(item) for item in items if isinstance(item, dict)]


def adapted_qos(profiles: Sequence[dict[str, Any]], default_depth: int = 10) -> dict[str, Any]:
    """The QoS to subscribe or replay with, by rosbag2's rule.

    Reliable only when every publisher offers reliable, transient local only when every publisher
    offers transient local (so a best-effort or volatile publisher still matches).
    """
    if not profiles:
        return {'reliability': 'reliable', 'durability': 'volatile', 'depth': default_depth}
    reliable = all(p.get('reliability') == 'reliable' for p in profiles)
    transient = all(p.get('durability') == 'transient_local' for p in profiles)
    depth = max([int(p.get('depth') or 0) for p in profiles] + [default_depth])
    return {'reliability': 'reliable' if reliable else 'best_effort',
            'durability': 'transient_local' if transient else 'volatile', 'depth': depth}


def compatible(offered: dict[str, Any], requested: dict[str, Any]) -> bool:
    """True when a publisher offering ``offered`` matches a subscription requesting ``requested``.

    DDS request/offered rule: a reliable reader needs a reliable writer, a transient-local reader
    needs a transient-local writer; the other combinations match.
    """
    if requested.get('reliability') == 'reliable' and offered.get('reliability') != 'reliable':
        return False
    return not (requested.get('durability') == 'transient_local'
                and offered.get('durability') != 'transient_local')


def resubscribe_qos(requested: dict[str, Any], profiles: Sequence[dict[str, Any]],
                    default_depth: int = 10) -> dict[str, Any] | None:
    """The QoS to subscribe again with when a publisher does not match ``requested``, else None.

    rosbag2 only warns that such a publisher ("offering best effort, but rosbag already
    subscribed requesting reliable") will not be recorded; we subscribe again with
    :func:`adapted_qos` over all publishers, which only ever relaxes the request, so the
    publishers matched before stay matched.
    """
    if all(compatible(p, requested) for p in profiles):
        return None
    return adapted_qos(profiles, default_depth)
