"""The lifecycle shared by the EEG nodes' ``main()``: init, spin until done, clean up."""

from __future__ import annotations

import sys
from collections.abc import Callable

from mindgrasp_eeg import EEGError
from mindgrasp_ros import rclpy
from mindgrasp_ros.process import exit_if_main_program


def run_node(factory: Callable[[], rclpy.node.Node], label: str,
             args: list[str] | None = None) -> int:
    """Run the node ``factory()`` makes until Ctrl-C or its ``done`` flag (the ``duration``
    parameter); exit 1 with the message of an :class:`EEGError` (bad input, lost stream).

    Run as a program, the process ends right after the node's cleanup (see
    :mod:`mindgrasp_ros.process`): within 1 s of SIGINT/SIGTERM in every state."""
    code = _run(factory, label, args)
    exit_if_main_program(code, getattr(factory, '__module__', ''))
    return code


def _run(factory: Callable[[], rclpy.node.Node], label: str, args: list[str] | None) -> int:
    rclpy.init(args=args)
    node = None
    try:
        node = factory()
        # one executor for the node's lifetime: cheap waits, no re-scan per spin
        executor = rclpy.executors.SingleThreadedExecutor()
        executor.add_node(node)
        while rclpy.ok() and not node.done:
            executor.spin_once(timeout_sec=0.1)
    except EEGError as exc:
        print(f'[{label}] ERROR: {exc}', file=sys.stderr, flush=True)
        return 1
    except KeyboardInterrupt:
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
