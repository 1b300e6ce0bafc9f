"""``rclpy.rate.Rate``: sleep at a fixed frequency of a clock (sim time aware)."""

from __future__ import annotations

from mindgrasp_ros.runtime.clock import Clock
from mindgrasp_ros.runtime.duration import Duration

__all__ = ['Rate']


class Rate:
    """Call :meth:`sleep` once per loop to run at ``frequency`` Hz on ``clock``."""

    def __init__(self, frequency: float, clock: Clock) -> None:
        if frequency <= 0:
            msg = f'Rate frequency must be positive, not {frequency!r} Hz.'
            raise ValueError(msg)
        self._period = Duration(seconds=1.0 / frequency)
        self._clock = clock
        self._next = clock.now() + self._period

    def sleep(self) -> None:
        self._clock.sleep_until(self._next)
        now = self._clock.now()
        self._next = self._next + self._period
        if self._next < now:
            self._next = now + self._period

    def destroy(self) -> None:
        pass
