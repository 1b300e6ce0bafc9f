"""The last line of a lock-step launch: the real-time factor of what was simulated, and no
absurd rate after a Ctrl-C before the first step (it read "real-time factor 0.0, 814159479.000
CPU s per simulated s")."""

from __future__ import annotations

from mindgrasp_launch.lockstep import run_lockstep
from mindgrasp_ros import rclpy
from mindgrasp_ros.graph.spec import NodeSpec


class CtrlCWhileComposing(rclpy.node.Node):
    """Ctrl-C arrives while the graph is being composed (nodes take seconds to construct)."""

    def __init__(self, **kwargs: object) -> None:
        super().__init__('ctrl_c', **kwargs)
        raise KeyboardInterrupt


class Idle(rclpy.node.Node):
    def __init__(self, **kwargs: object) -> None:
        super().__init__('idle', **kwargs)


def _last_line(node_class: type, duration_s: float) -> tuple[int, str]:
    lines: list[str] = []
    component = NodeSpec('n', f'{__name__}:{node_class.__name__}')
    code = run_lockstep([component], duration_s=duration_s, log=lines.append)
    return code, lines[-1]


def test_a_stop_before_the_first_step_reports_no_rate():
    code, line = _last_line(CtrlCWhileComposing, 0.0)
    assert code == 0
    assert line.startswith('lock-step: stopped after ') and 'before the first simulated step' \
        in line, line
    assert 'CPU s per simulated s' not in line


def test_a_run_reports_its_real_time_factor():
    code, line = _last_line(Idle, 0.2)
    assert code == 0
    assert line.startswith('lock-step: simulated 0.2 s in '), line
    assert 'real-time factor' in line and 'CPU s per simulated s' in line
