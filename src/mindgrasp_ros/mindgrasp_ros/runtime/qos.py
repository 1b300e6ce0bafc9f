"""QoS profiles, policies and presets with rclpy's names (``rclpy.qos``)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field, replace

from mindgrasp_ros.runtime.duration import Duration

__all__ = [
    'DurabilityPolicy', 'HistoryPolicy', 'LivelinessPolicy', 'QoSPresetProfiles', 'QoSProfile',
    'ReliabilityPolicy', 'qos_profile_action_status_default', 'qos_profile_clock',
    'qos_profile_parameter_events', 'qos_profile_parameters', 'qos_profile_rosout_default',
    'qos_profile_sensor_data', 'qos_profile_services_default', 'qos_profile_system_default',
]


class HistoryPolicy(enum.IntEnum):
    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3


class ReliabilityPolicy(enum.IntEnum):
    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class DurabilityPolicy(enum.IntEnum):
    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class LivelinessPolicy(enum.IntEnum):
    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_NODE = 2
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5


# rclpy's old aliases
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy


@dataclass
class QoSProfile:
    """A ROS QoS profile. ``QoSProfile(depth=10)`` is KEEP_LAST 10, RELIABLE, VOLATILE.

    As in rclpy, ``history`` defaults to KEEP_LAST and a profile needs ``depth`` (or KEEP_ALL).
    """

    history: HistoryPolicy = HistoryPolicy.KEEP_LAST
    depth: int = 10
    reliability: ReliabilityPolicy = ReliabilityPolicy.RELIABLE
    durability: DurabilityPolicy = DurabilityPolicy.VOLATILE
    lifespan: Duration = field(default_factory=Duration)
    deadline: Duration = field(default_factory=Duration)
    liveliness: LivelinessPolicy = LivelinessPolicy.SYSTEM_DEFAULT
    liveliness_lease_duration: Duration = field(default_factory=Duration)
    avoid_ros_namespace_conventions: bool = False

    def __post_init__(self) -> None:
        self.history = HistoryPolicy(self.history)
        self.reliability = ReliabilityPolicy(self.reliability)
        self.durability = DurabilityPolicy(self.durability)
        self.liveliness = LivelinessPolicy(self.liveliness)
        if self.history == HistoryPolicy.SYSTEM_DEFAULT:
            self.history = HistoryPolicy.KEEP_LAST
        if self.reliability in (ReliabilityPolicy.SYSTEM_DEFAULT,
                                ReliabilityPolicy.BEST_AVAILABLE):
            self.reliability = ReliabilityPolicy.RELIABLE
        if self.durability in (DurabilityPolicy.SYSTEM_DEFAULT, DurabilityPolicy.BEST_AVAILABLE):
            self.durability = DurabilityPolicy.VOLATILE
        if not isinstance(self.depth, int) or self.depth < 0:
            msg = f'QoSProfile depth must be a non-negative int, not {self.depth!r}.'
            raise ValueError(msg)

    def copy(self, **changes: object) -> QoSProfile:
        return replace(self, **changes)

    def is_compatible_with(self, writer: QoSProfile) -> bool:
        """Whether a reader with this profile matches a writer with ``writer`` (DDS rules)."""
        if (self.reliability == ReliabilityPolicy.RELIABLE
                and writer.reliability == ReliabilityPolicy.BEST_EFFORT):
            return False
        return not (self.durability == DurabilityPolicy.TRANSIENT_LOCAL
                    and writer.durability == DurabilityPolicy.VOLATILE)


qos_profile_system_default = QoSProfile(depth=10)
qos_profile_sensor_data = QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)
qos_profile_services_default = QoSProfile(depth=10)
qos_profile_parameters = QoSProfile(depth=1000)
qos_profile_parameter_events = QoSProfile(depth=1000)
qos_profile_rosout_default = QoSProfile(
    depth=1000, durability=DurabilityPolicy.TRANSIENT_LOCAL,
    lifespan=Duration(seconds=10))
qos_profile_action_status_default = QoSProfile(
    depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
qos_profile_clock = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)


class QoSPresetProfiles(enum.Enum):
    SYSTEM_DEFAULT = qos_profile_system_default
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = qos_profile_services_default
    PARAMETERS = qos_profile_parameters
    PARAMETER_EVENTS = qos_profile_parameter_events
    ACTION_STATUS_DEFAULT = qos_profile_action_status_default

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        return cls[name.upper()].value


def as_profile(qos_or_depth: QoSProfile | int) -> QoSProfile:
    """rclpy accepts a profile or a history depth wherever QoS is asked for."""
    if isinstance(qos_or_depth, QoSProfile):
        return qos_or_depth
    if isinstance(qos_or_depth, int) and not isinstance(qos_or_depth, bool):
        return QoSProfile(depth=qos_or_depth)
    msg = f'QoS must be a QoSProfile or a history depth (int), not {qos_or_depth!r}.'
    raise TypeError(msg)
