"""Fixture node written with the skeleton: ticks, ends after ``duration`` s or ``cycles`` ticks,
or fails with ``fail_after`` ticks; ``gain`` is live, ``label`` read-only."""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass

from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import end_after, fail, run_node
from mindgrasp_ros.params import declare_params, param


@dataclass
class TickerParams:
    rate: float = param(20.0, 'ticks per second', unit='Hz', min=1.0, max=200.0)
    gain: float = param(1.0, 'value added per tick', min=0.0, max=10.0, live=True)
    label: str = param('tick', 'prefix of each log line')
    cycles: int = param(0, 'ticks before the node ends (0: no limit)', min=0)
    fail_after: int = param(0, 'ticks before the node fails (0: never)', min=0)
    end_code: int = param(0, "the exit code 'done' holds after 'cycles' ticks", min=0, max=125)
    duration: float = param(0.0, 'end after this long (0: run until stopped)', unit='s',
                            min=0.0)

    def __post_init__(self) -> None:
        if self.cycles and self.fail_after and self.fail_after >= self.cycles:
            msg = f"'fail_after' ({self.fail_after}) must be below 'cycles' ({self.cycles})."
            raise ValueError(msg)


class Ticker(rclpy.node.Node):
    def __init__(self, **kwargs) -> None:
        super().__init__('skeleton_ticker', **kwargs)
        self.done = rclpy.task.Future()
        self.params = declare_params(self, TickerParams)
        self.ticks = 0
        self.total = 0.0
        self.create_timer(1.0 / self.params.rate, self.timer_callback)
        end_after(self, self.params.duration)
        self.get_logger().info('ready')

    def timer_callback(self) -> None:
        self.ticks += 1
        self.total += self.params.gain
        self.get_logger().info(f'{os.getpid()} {self.params.label} {self.ticks} total '
                               f'{self.total:g}',
                               throttle_duration_sec=0.2)
        if self.params.fail_after and self.ticks >= self.params.fail_after:
            fail(self, f'failed after {self.ticks} ticks as asked')
        elif self.params.cycles and self.ticks >= self.params.cycles:
            self.done.set_result(self.params.end_code)

    def destroy_node(self) -> None:
        print(f'ran {self.ticks} ticks', flush=True)
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    return run_node(Ticker, args)


if __name__ == '__main__':
    sys.exit(main())
