"""Conversions between ROS messages and the plain types of this package.

Only duck-typed attribute access on messages; no ROS import, so tests can use any message class.
"""

from __future__ import annotations

from collections.abc import Sequence

from .acquisition import ERROR, OK, WARN, Status


def time_to_s(stamp: object) -> float:
    """``builtin_interfaces/Time`` -> seconds."""
    return float(stamp.sec) + 1e-9 * float(stamp.nanosec)


def ns_to_time_fields(ns: int) -> tuple[int, int]:
    """Nanoseconds -> (sec, nanosec) of ``builtin_interfaces/Time``."""
    return int(ns // 1_000_000_000), int(ns % 1_000_000_000)


def base_yaw_from_joint_state(names: Sequence[str], positions: Sequence[float],
                              joint: str = '') -> float | None:
    """Base joint angle (rad): ``joint`` if given, else the first joint (/joint_states lists the
    arm joints base to wrist, in the order of the robot description)."""
    names = list(names)
    if not names or len(positions) == 0:
        return None
    if joint and joint in names:
        return float(positions[names.index(joint)])
    if joint:
        return None
    return float(positions[0])


def status_level_byte(level: int) -> bytes | int:
    """DiagnosticStatus level (OK 0, WARN 1, ERROR 2) as the message field wants it."""
    return {OK: 0, WARN: 1, ERROR: 2}[level]


def status_values(status: Status) -> list[tuple[str, str]]:
    """Key/value pairs of a status, sorted by key."""
    return sorted(status.values.items())
