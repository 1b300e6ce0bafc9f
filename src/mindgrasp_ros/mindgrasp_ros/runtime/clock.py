"""``rclpy.clock``: system, steady and ROS clocks; ROS time follows /clock when use_sim_time."""

from __future__ import annotations

import threading
import time as _time
from collections.abc import Callable

from mindgrasp_ros.runtime.clock_type import ClockType
from mindgrasp_ros.runtime.duration import Duration
from mindgrasp_ros.runtime.time import Time

__all__ = ['Clock', 'ClockType', 'ROSClock']


class Clock:
    """A clock of one :class:`ClockType`. ``now()`` returns a :class:`Time`."""

    def __init__(self, *, clock_type: ClockType = ClockType.SYSTEM_TIME) -> None:
        self._clock_type = ClockType(clock_type)
        self._override_ns: int | None = None
        self._cond = threading.Condition()
        self._listeners: list[Callable[[], None]] = []

    @property
    def clock_type(self) -> ClockType:
        return self._clock_type

    def now(self) -> Time:
        return Time(nanoseconds=self.now_ns(), clock_type=self._clock_type)

    def now_ns(self) -> int:
        """``now().nanoseconds`` without building a :class:`Time` (ns). Not in rclpy: timers ask
        it on every executor round, and a lock-step run has thousands of rounds per trial."""
        override = self._override_ns
        if override is not None:
            return override
        if self._clock_type == ClockType.STEADY_TIME:
            return _time.monotonic_ns()
        return _time.time_ns()

    # ROS time override (used by the time source for use_sim_time, and by lock-step runs)
    @property
    def ros_time_is_active(self) -> bool:
        return self._override_ns is not None

    def set_ros_time_override_ns(self, nanoseconds: int | None) -> None:
        """ROS time from now on (ns; None: system time again), as the time source sets it
        for ``use_sim_time`` (rclpy's ``set_ros_time_override`` takes a Time)."""
        with self._cond:
            self._override_ns = nanoseconds
            self._cond.notify_all()
        for listener in list(self._listeners):
            listener()

    def _add_time_listener(self, callback: Callable[[], None]) -> None:
        self._listeners.append(callback)

    def sleep_until(self, until: Time, context=None) -> bool:
        """Sleep until the clock reaches ``until``; works with sim time too."""
        while True:
            remaining = until.nanoseconds - self.now().nanoseconds
            if remaining <= 0:
                return True
            with self._cond:
                if self._override_ns is not None:
                    self._cond.wait(timeout=0.1)
                else:
                    self._cond.wait(timeout=remaining / 1e9)

    def sleep_for(self, rel_time: Duration, context=None) -> bool:
        return self.sleep_until(self.now() + rel_time, context)

    def __repr__(self) -> str:
        return f'Clock(clock_type={self._clock_type.name})'


class ROSClock(Clock):
    """The ROS clock: wall time, or the latest /clock time while ``use_sim_time`` is true."""

    def __init__(self) -> None:
        super().__init__(clock_type=ClockType.ROS_TIME)
