"""The node skeleton (``run_node``), declared parameters and the topic table, with real processes.

The fixture node ``skeleton_node.py`` is written the way every node is: a dataclass of
parameters, ``done`` Future, ``main() = run_node(...)``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from mindgrasp_testing import spin_until

HERE = Path(__file__).resolve().parent
NODE = str(HERE / 'skeleton_node.py')
REPO = HERE.parents[1]


def _params(**values) -> list[str]:
    out = ['--ros-args']
    for k, v in values.items():
        out += ['-p', f'{k}:={v}']
    return out


def test_node_ends_by_itself_after_a_count_or_a_duration(spawn_node):
    by_count = spawn_node(NODE, *_params(cycles=5, rate=50.0))
    by_time = spawn_node(NODE, *_params(duration=0.5))
    assert by_count.wait(60) == 0, by_count.output()
    assert by_time.wait(60) == 0, by_time.output()
    assert 'ran 5 ticks' in by_count.output()
    assert 'ran ' in by_time.output()


def test_failure_while_running_is_exit_1_with_one_line(spawn_node):
    proc = spawn_node(NODE, *_params(fail_after=3))
    assert proc.wait(60) == 1
    out = proc.output()
    assert '[skeleton_ticker] ERROR: failed after 3 ticks as asked' in out
    assert 'Traceback' not in out


@pytest.mark.parametrize(('values', 'match'), [
    ({'rate': 0.5}, "Invalid value 0.5 for parameter 'rate': must be within [1.0, 200.0]"),
    ({'cycles': 3, 'fail_after': 4}, "'fail_after' (4) must be below 'cycles' (3)."),
])
def test_bad_parameter_refuses_to_start_with_exit_2(spawn_node, values, match):
    proc = spawn_node(NODE, *_params(**values))
    assert proc.wait(60) == 2
    out = proc.output()
    assert match in out and 'Traceback' not in out, out


def test_ctrl_c_is_a_clean_stop(spawn_node):
    proc = spawn_node(NODE)
    assert proc.wait_for_output('tick 1 ', 60), proc.output()   # spinning
    assert proc.stop() == 0
    assert 'ran ' in proc.output()


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=120)


def test_param_describe_set_live_and_read_only(spawn_node, rclpy_ctx):
    proc = spawn_node(NODE)
    assert proc.wait_for_output('ready', 60), proc.output()
    out = _cli('param', 'describe', '/skeleton_ticker', 'rate', 'gain')
    assert out.returncode == 0, out.stderr
    assert 'Parameter name: rate\n  Type: double\n  Description: ticks per second [Hz]\n' \
        '  Constraints:\n    Read only: true\n    Min value: 1.0\n    Max value: 200.0' \
        in out.stdout, out.stdout
    assert 'Additional constraints: live: applied at once' in out.stdout
    # read-only: refused with the reason
    out = _cli('param', 'set', '/skeleton_ticker', 'label', 'tock')
    assert out.returncode == 1 and "'label' is read-only: restart the node" in out.stderr
    # out of range: refused with the range
    out = _cli('param', 'set', '/skeleton_ticker', 'gain', '-1')
    assert out.returncode == 1 and 'must be within [0.0, 10.0]' in out.stderr, out.stderr
    # a valid live change takes effect: the total grows by the new gain per tick
    out = _cli('param', 'set', '/skeleton_ticker', 'gain', '0')
    assert out.returncode == 0 and 'Set parameter successful' in out.stdout, out.stderr
    assert proc.wait_for_output('Parameter change applied: gain=0.0', 60), proc.output()
    node = rclpy_ctx.node.Node('skeleton_probe')
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import Log

    totals = []
    pid = str(proc.proc.pid)  # the logger name is shared; keep to this process's lines
    node.create_subscription(Log, '/rosout', lambda m: totals.append(m.msg)
                             if m.name == 'skeleton_ticker' and m.msg.startswith(pid) else None,
                             100)
    assert spin_until(node, lambda: len(totals) >= 3, 60.0)
    assert len({t.split(' total ')[1] for t in totals[-3:]}) == 1, totals  # gain 0: constant
    node.destroy_node()


def test_describe_refuses_an_undeclared_name(spawn_node):
    proc = spawn_node(NODE)
    assert proc.wait_for_output('ready', 60), proc.output()
    out = _cli('param', 'describe', '/skeleton_ticker', 'nope')
    assert out.returncode == 1 and "'nope' is not declared on /skeleton_ticker" in out.stderr


def test_topic_table_is_the_readme_table():
    from mindgrasp_ros.topics import markdown_table

    readme = (REPO / 'README.md').read_text()
    assert markdown_table() in readme, (
        'The README topic table differs from mindgrasp_ros/topics.py; paste the output of '
        '`python -m mindgrasp_ros.topics` into README.md:\n' + markdown_table())


def test_every_topic_has_a_known_message_type_and_qos():
    from mindgrasp_ros.topics import TOPICS

    for t in TOPICS.values():
        assert t.msg_class.__name__ == t.type.rsplit('/', 1)[1]
        assert t.qos.depth >= 1
