"""``rclpy.timer.Timer``: calls back every period of its clock (ROS time follows /clock)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from mindgrasp_ros.runtime.callback_groups import CallbackGroup
from mindgrasp_ros.runtime.clock import Clock
from mindgrasp_ros.runtime.entity import Entity

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.node import Node

__all__ = ['Timer']


class Timer(Entity):
    """Calls back every ``timer_period_ns`` of its clock (ROS time follows /clock)."""

    def __init__(self, node: Node, period_sec: float, callback: Callable | None,
                 callback_group: CallbackGroup | None, clock: Clock,
                 autostart: bool = True) -> None:
        super().__init__(node, callback_group)
        if not period_sec >= 0:
            msg = f'Timer period must be a non-negative number of seconds, not {period_sec!r}.'
            raise ValueError(msg)
        self.timer_period_ns = round(period_sec * 1e9)
        self.callback = callback
        self.clock = clock
        self._canceled = not autostart
        self._next_ns = clock.now().nanoseconds + self.timer_period_ns
        self._last_ns = clock.now().nanoseconds

    def is_canceled(self) -> bool:
        """Whether the timer is canceled (a method, as rclpy's)."""
        return self._canceled

    def cancel(self) -> None:
        self._canceled = True

    def reset(self) -> None:
        self._canceled = False
        now = self.clock.now().nanoseconds
        self._next_ns = now + self.timer_period_ns
        self._last_ns = now
        self.node.wake_executor()

    def is_ready(self) -> bool:
        """Whether a period has elapsed since the last call (``rclpy.timer.Timer.is_ready``);
        the executor then takes it with :meth:`call_timer`."""
        if self._canceled:
            return False
        now = self.clock.now_ns()
        if now < self._last_ns:  # time jumped back (sim time restarted): restart the period
            self._last_ns = now
            self._next_ns = now + self.timer_period_ns
            return False
        return now >= self._next_ns

    def time_until_next_call(self) -> int | None:
        """Nanoseconds until due (None when canceled)."""
        if self._canceled:
            return None
        return max(0, self._next_ns - self.clock.now_ns())

    def time_since_last_call(self) -> int:
        return self.clock.now_ns() - self._last_ns

    def call_timer(self) -> None:
        """Take a ready timer: its next period starts now (the executor then runs
        :meth:`execute`), as rcl's ``rcl_timer_call`` behind rclpy's ``_take_timer``."""
        now = self.clock.now_ns()
        self._last_ns = now
        self._next_ns += self.timer_period_ns
        if self._next_ns <= now:  # missed periods: skip them, as rcl does
            missed = (now - self._next_ns) // max(1, self.timer_period_ns) + 1
            self._next_ns += missed * self.timer_period_ns

    def execute(self, _item: object = None) -> None:
        if self.callback is not None:
            self.callback()
