"""Conversions between ROS messages and the plain types of this package.

Only duck-typed attribute access on messages; no ROS import, so tests can use any message class.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from .acquisition import ERROR, OK, WARN, Status
from .subject import SceneObject

_COLOURS = {'red': (1.0, 0.0, 0.0), 'yellow': (1.0, 1.0, 0.0), 'blue': (0.0, 0.0, 1.0)}
_SHAPES_BY_MARKER_TYPE = {1: 'cube', 2: 'sphere', 3: 'cylinder'}   # visualization_msgs/Marker
_MARKER_DELETE, _MARKER_DELETEALL, _MARKER_TEXT = 2, 3, 9


def time_to_s(stamp: object) -> float:
    """``builtin_interfaces/Time`` -> seconds."""
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def ns_to_time_fields(ns: int) -> tuple[int, int]:
    """Nanoseconds -> (sec, nanosec) of ``builtin_interfaces/Time``."""
    return int(ns // 1_000_000_000), int(ns % 1_000_000_000)


def markers_to_objects(markers: Iterable[object], base_xy: Sequence[float] = (0.0, 0.0)
                       ) -> list[SceneObject]:
    """``visualization_msgs/MarkerArray.markers`` -> scene objects in the arm base frame.

    Colour from the marker text or namespace (``red``/``yellow``/``blue``), else the nearest of
    those to the marker colour; shape from the text or namespace (``cube``/``cylinder``/
    ``sphere``), else from the marker type. Text-only and delete markers are skipped. Positions are
    taken in the world frame with the arm base at ``base_xy`` (m).
    """
    out = []
    for m in markers:
        if m.action in (_MARKER_DELETE, _MARKER_DELETEALL) or m.type == _MARKER_TEXT:
            continue
        words = f'{m.text} {m.ns}'.lower().replace('_', ' ').replace('/', ' ').split()
        colour = next((w for w in words if w in _COLOURS), '')
        if not colour:
            rgb = np.array([m.color.r, m.color.g, m.color.b])
            colour = min(_COLOURS, key=lambda c: float(np.sum((rgb - _COLOURS[c]) ** 2)))
        shape = next((w for w in words if w in ('cube', 'cylinder', 'sphere')),
                     _SHAPES_BY_MARKER_TYPE.get(int(m.type), 'unknown'))
        p = m.pose.position
        out.append(SceneObject(int(m.id), colour, shape, float(p.x) - base_xy[0],
                               float(p.y) - base_xy[1], float(p.z)))
    return out


def base_yaw_from_joint_state(names: Sequence[str], positions: Sequence[float],
                              joint: str = '') -> float | None:
    """Base joint angle (rad): ``joint`` if given, else ``joint_1``, else the first joint."""
    names = list(names)
    if not names or len(positions) == 0:
        return None
    if joint and joint in names:
        return float(positions[names.index(joint)])
    if joint:
        return None
    return float(positions[names.index('joint_1') if 'joint_1' in names else 0])


def status_level_byte(level: int) -> bytes | int:
    """DiagnosticStatus level (OK 0, WARN 1, ERROR 2) as the message field wants it."""
    return {OK: 0, WARN: 1, ERROR: 2}[level]


def status_values(status: Status) -> list[tuple[str, str]]:
    """Key/value pairs of a status, sorted by key."""
    return sorted(status.values.items())
