"""One definition of a node's end and exit code for every graph host: a node alone in its
process (``run_node``), composed in one process (the ``--composed`` container, ``run_composed``)
and lock-step on simulated time (``run_lockstep``), with the scheduler an ``Executor`` subclass
that reads only the runtime's public readiness API."""

from __future__ import annotations

import os
import re
from pathlib import Path

import yaml

from mindgrasp_ros.runtime.executors import Executor, LockstepExecutor

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / 'src'
NODE = str(HERE / 'skeleton_node.py')
#: the fixture node ends after 3 ticks with exit code 3 (as a prompter that gave up)
ENDS_WITH_3 = ['--ros-args', '-p', 'cycles:=3', '-p', 'end_code:=3', '-p', 'rate:=50.0']
LINE = '[skeleton_ticker] ERROR: ended with exit code 3'


def test_a_node_alone_exits_with_its_own_code(spawn_node):
    proc = spawn_node(NODE, *ENDS_WITH_3)
    assert proc.wait(60) == 3, proc.output()
    assert 'Traceback' not in proc.output()


def test_a_composed_graph_fails_when_a_node_ends_with_a_code(spawn_node, tmp_path):
    plan = tmp_path / 'composed.yaml'
    plan.write_text(yaml.safe_dump({'components': [
        {'label': 'ticker', 'module': 'skeleton_node', 'ros_args': ENDS_WITH_3}]}))
    path = os.pathsep.join([str(HERE), os.environ.get('PYTHONPATH', '')])
    proc = spawn_node('mindgrasp_launch.container', str(plan),
                      env={'PYTHONPATH': path})
    assert proc.wait(60) == 1, proc.output()
    assert LINE in proc.output()
    assert 'Traceback' not in proc.output()


def test_a_lockstep_graph_fails_when_a_node_ends_with_a_code(monkeypatch):
    from mindgrasp_launch.lockstep import run_lockstep
    from mindgrasp_ros.graph.spec import NodeSpec

    monkeypatch.syspath_prepend(str(HERE))
    lines: list[str] = []
    comp = NodeSpec('ticker', 'skeleton_node', ros_args=ENDS_WITH_3[1:])
    assert run_lockstep([comp], step_s=0.02, duration_s=30.0, log=lines.append) == 1
    assert LINE in lines, lines


def test_the_lockstep_scheduler_is_an_executor_of_the_runtime():
    from mindgrasp_ros.graph.lockstep import LockstepRunner

    with LockstepRunner() as runner:
        assert isinstance(runner.executor, LockstepExecutor)
        assert isinstance(runner.executor, Executor)


def test_lockstep_runs_guards_and_skips_canceled_timers():
    """Through the entities' own API: a triggered guard runs once, a canceled timer never."""
    from mindgrasp_ros.graph.lockstep import LockstepRunner
    from mindgrasp_ros.runtime.node import Node

    calls: list[str] = []
    with LockstepRunner() as runner:
        node = runner.add(Node, 'hosted')
        timer = node.create_timer(0.1, lambda: calls.append('timer'))
        guard = node.create_guard_condition(lambda: calls.append('guard'))
        runner.step(0.1)
        assert calls == ['timer']
        timer.cancel()
        guard.trigger()
        runner.step(0.1)
        runner.step(0.1)
        assert calls == ['timer', 'guard']


# `x._name` where x is not self/cls: another object's private attribute
_FOREIGN_PRIVATE = re.compile(r'\b(?!self\b|cls\b)[A-Za-z_]\w*\._[a-z]\w*')


def test_the_graph_hosts_read_no_private_field_of_another_object():
    hosts = [*(SRC / 'mindgrasp_ros' / 'mindgrasp_ros' / 'graph').glob('*.py'),
             SRC / 'mindgrasp_launch' / 'mindgrasp_launch' / 'lockstep.py']
    found = [f'{path.name}:{n}: {line.strip()}' for path in hosts
             for n, line in enumerate(path.read_text().splitlines(), 1)
             if _FOREIGN_PRIVATE.search(line.split('#')[0])]
    assert not found, '\n'.join(found)


def test_a_node_reports_the_entities_given_work_in_the_executors_order():
    """Arrival order does not matter: subscriptions, then services, then guard conditions, each
    in creation order, as a full scan would take them (the lock-step order, hence the records)."""
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros.graph.lockstep import LockstepRunner
    from mindgrasp_ros.runtime.node import Node

    with LockstepRunner() as runner:
        node = runner.add(Node, 'hosted')
        guard = node.create_guard_condition(lambda: None)
        first = node.create_subscription(String, '/a', lambda _m: None, 10)
        second = node.create_subscription(String, '/b', lambda _m: None, 10)
        pub_a = node.create_publisher(String, '/a', 10)
        pub_b = node.create_publisher(String, '/b', 10)
        assert node.take_ready_entities() is None           # entities changed: look at all
        guard.trigger()
        pub_b.publish(String(data='b'))
        pub_a.publish(String(data='a'))
        pub_b.publish(String(data='b again'))
        assert node.take_ready_entities() == [first, second, guard]
        assert node.take_ready_entities() == []


def test_the_lockstep_executor_reads_every_parameter_it_takes():
    """No parameter of LockstepExecutor's methods is ignored or overwritten before it is read
    (``_collect(self, ready=None)`` took a readiness set and replaced it unread)."""
    import ast
    import inspect
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(LockstepExecutor)))
    unread = []
    for func in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)):
        params = [a.arg for a in func.args.args[1:] + func.args.kwonlyargs]
        names = sorted((n for n in ast.walk(func) if isinstance(n, ast.Name)),
                       key=lambda n: (n.lineno, n.col_offset))
        for name in params:
            first = next((n for n in names if n.id == name), None)
            if first is None or not isinstance(first.ctx, ast.Load):
                unread.append(f'{func.name}({name})')
    # _spin_once_impl(timeout_sec) is rclpy's signature: lock-step never waits
    assert unread == ['_spin_once_impl(timeout_sec)'], unread
