"""``rclpy.duration.Duration``."""

from __future__ import annotations

from functools import total_ordering

__all__ = ['Duration', 'Infinite']


@total_ordering
class Duration:
    """A signed span of time in nanoseconds."""

    __slots__ = ('_nanoseconds',)

    def __init__(self, *, seconds: float = 0, nanoseconds: int = 0) -> None:
        self._nanoseconds = round(seconds * 1e9) + int(nanoseconds)

    @property
    def nanoseconds(self) -> int:
        return self._nanoseconds

    def to_msg(self):
        from mindgrasp_ros.typesupport import get_message_class

        sec, nsec = divmod(self._nanoseconds, 1_000_000_000)
        return get_message_class('builtin_interfaces/msg/Duration')(sec=sec, nanosec=nsec)

    @classmethod
    def from_msg(cls, msg) -> Duration:
        return cls(seconds=msg.sec, nanoseconds=msg.nanosec)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Duration):
            return NotImplemented
        return self._nanoseconds == other._nanoseconds

    def __lt__(self, other: Duration) -> bool:
        return self._nanoseconds < other._nanoseconds

    def __hash__(self) -> int:
        return hash(self._nanoseconds)

    def __repr__(self) -> str:
        return f'Duration(nanoseconds={self._nanoseconds})'


Infinite = Duration(nanoseconds=2**63 - 1)
