"""``rclpy.time.Time``."""

from __future__ import annotations

from functools import total_ordering

from mindgrasp_ros.runtime.clock_type import ClockType
from mindgrasp_ros.runtime.duration import Duration

__all__ = ['Time']


@total_ordering
class Time:
    """A point in time (ns since the epoch of its clock type)."""

    __slots__ = ('_clock_type', '_nanoseconds')

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0,
                 clock_type: ClockType = ClockType.SYSTEM_TIME) -> None:
        total = round(seconds * 1e9) + int(nanoseconds)
        if total < 0:
            msg = 'Time cannot be negative; use a Duration for signed spans.'
            raise ValueError(msg)
        self._nanoseconds = total
        self._clock_type = ClockType(clock_type)

    @property
    def nanoseconds(self) -> int:
        return self._nanoseconds

    @property
    def clock_type(self) -> ClockType:
        return self._clock_type

    def seconds_nanoseconds(self) -> tuple[int, int]:
        return divmod(self._nanoseconds, 1_000_000_000)

    def to_msg(self):
        from mindgrasp_ros.typesupport import get_message_class

        sec, nsec = self.seconds_nanoseconds()
        return get_message_class('builtin_interfaces/msg/Time')(sec=sec, nanosec=nsec)

    @classmethod
    def from_msg(cls, msg, clock_type: ClockType = ClockType.ROS_TIME) -> Time:
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec, clock_type=clock_type)

    def __add__(self, other: Duration) -> Time:
        if not isinstance(other, Duration):
            return NotImplemented
        return Time(nanoseconds=self._nanoseconds + other.nanoseconds,
                    clock_type=self._clock_type)

    __radd__ = __add__

    def __sub__(self, other: Time | Duration) -> Time | Duration:
        if isinstance(other, Time):
            if other._clock_type != self._clock_type:
                msg = "Can't subtract times with different clock types."
                raise TypeError(msg)
            return Duration(nanoseconds=self._nanoseconds - other._nanoseconds)
        if isinstance(other, Duration):
            return Time(nanoseconds=self._nanoseconds - other.nanoseconds,
                        clock_type=self._clock_type)
        return NotImplemented

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Time):
            return NotImplemented
        return (self._nanoseconds, self._clock_type) == (other._nanoseconds, other._clock_type)

    def __lt__(self, other: Time) -> bool:
        if other._clock_type != self._clock_type:
            msg = "Can't compare times with different clock types."
            raise TypeError(msg)
        return self._nanoseconds < other._nanoseconds

    def __hash__(self) -> int:
        return hash((self._nanoseconds, self._clock_type))

    def __repr__(self) -> str:
        return f'Time(nanoseconds={self._nanoseconds}, clock_type={self._clock_type.name})'
