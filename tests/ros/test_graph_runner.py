"""One graph host, three schedulers: the same NodeSpec graph run a process per node (real DDS
between real processes), all in one process, and lock-step on simulated time ends the same way,
with one exit code; parameters reach the node typed (never through ``-p name:=value`` text)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from mindgrasp_ros.graph.host import GraphRunner, InProcess, Lockstep, Processes
from mindgrasp_ros.graph.spec import NodeSpec

HERE = Path(__file__).resolve().parent
#: the fixture node ends after 3 ticks with exit code 3; its label is text that reads as a number
TICKER = NodeSpec('ticker', 'skeleton_node', parameters={
    'cycles': 3, 'end_code': 3, 'rate': 50.0, 'label': '0.5'})


@pytest.fixture
def on_path(monkeypatch) -> dict[str, str]:
    """skeleton_node importable here and in child processes."""
    monkeypatch.syspath_prepend(str(HERE))
    path = os.pathsep.join([str(HERE), os.environ.get('PYTHONPATH', '')])
    return {**os.environ, 'PYTHONPATH': path}


def test_every_scheduler_ends_the_graph_with_one_exit_code(on_path, tmp_path):
    for scheduler in (Lockstep(0.02), InProcess(), Processes(tmp_path, env=on_path)):
        lines: list[str] = []
        code = GraphRunner(scheduler, log=lines.append).run([TICKER], duration_s=60.0)
        assert code == 1, (type(scheduler).__name__, lines)
        assert any(line.endswith('ERROR: ended with exit code 3') for line in lines), lines
        assert scheduler.time_s < 60.0, type(scheduler).__name__   # ended by the node, not time


def test_a_process_per_node_writes_typed_parameters_and_logs(on_path, tmp_path):
    """A str parameter whose text reads as a float stays a str in the node's own process (as
    ``-p label:=0.5`` it would be refused as a double): the label is on each tick's line."""
    scheduler = Processes(tmp_path, env=on_path)
    assert GraphRunner(scheduler, log=lambda _l: None).run([TICKER], duration_s=60.0) == 1
    log = (tmp_path / 'ticker.log').read_text()
    assert ' 0.5 1 total 1' in log, log
    assert "label: '0.5'" in (tmp_path / 'params' / 'ticker.yaml').read_text()


def test_lockstep_gives_the_parameters_typed_and_they_win(on_path):
    spec = TICKER.with_parameters({'cycles': 0, 'gain': 2})
    with GraphRunner(Lockstep(0.02)) as graph:
        node = graph.add(NodeSpec(spec.label, spec.module, parameters=spec.parameters,
                                  ros_args=['-p', 'label:=from_text', '-p', 'rate:=10.0']))
        graph.spin_until(lambda: node.ticks >= 2, limit_s=10.0)
    assert node.params.label == '0.5' and node.params.rate == 50.0
    assert node.params.gain == 2.0 and node.total == 2.0 * node.ticks
    assert TICKER.parameters['cycles'] == 3                    # with_parameters copies


def test_a_graph_stops_after_its_duration_on_the_schedulers_clock(on_path):
    forever = TICKER.with_parameters({'cycles': 0})
    scheduler = Lockstep(0.05)
    assert GraphRunner(scheduler, log=lambda _l: None).run([forever], duration_s=2.0) == 0
    assert scheduler.time_s == pytest.approx(2.0)


class _Command:
    """A process built by its caller, as the launcher builds its own (a ``ProcessHandle``)."""

    def __init__(self, label: str, code: str, stopped: list[str]) -> None:
        import concurrent.futures

        self.label, self.code, self.stopped = label, code, stopped
        self.done: concurrent.futures.Future[int] = concurrent.futures.Future()
        self.process = None

    def get_name(self) -> str:
        return self.label

    def start(self) -> None:
        import subprocess
        import sys

        self.process = subprocess.Popen([sys.executable, '-c', self.code])

    def poll(self) -> None:
        if self.process.poll() is not None and not self.done.done():
            self.done.set_result(self.process.returncode)

    def destroy_node(self) -> None:
        self.stopped.append(self.label)
        if self.process.poll() is None:
            self.process.terminate()
        self.process.wait(60)
        self.poll()


def test_processes_host_a_callers_own_processes_in_the_same_order(tmp_path):
    """The launcher's processes are hosted by the same scheduler: started when added, polled
    until one has ended (``is_done``), then stopped newest first (``end_graph``)."""
    from mindgrasp_ros.node_main import is_done

    stopped: list[str] = []
    runner = GraphRunner(Processes(tmp_path))
    first = runner.add(_Command('first', 'import time; time.sleep(120)', stopped))
    middle = runner.add(_Command('middle', 'import time; time.sleep(120)', stopped))
    last = runner.add(_Command('last', 'raise SystemExit(3)', stopped))
    runner.spin_until(runner.ended, 60.0)
    assert is_done(last) and last.done.result() == 3
    assert not is_done(first) and not is_done(middle)
    runner.close()
    assert stopped == ['last', 'middle', 'first']
    assert all(is_done(c) for c in (first, middle, last))


@pytest.mark.parametrize('scheduler', [lambda: Lockstep(0.02), InProcess], ids=['lockstep',
                                                                               'in_process'])
def test_a_composed_graph_keeps_its_names_remaps_and_typed_parameters(monkeypatch, scheduler):
    """What tests/ros2_real/test_ros2_composed.py checks on the real rclpy: the host passes
    ``cli_args`` and ``parameter_overrides`` to the node classes, as rclpy's Node takes them."""
    monkeypatch.syspath_prepend(str(HERE.parent / 'bringup'))
    remaps = {'chatter': '/composed/chatter'}
    with GraphRunner(scheduler()) as graph:
        talker = graph.add(NodeSpec('talker', 'launch_fixtures.talker', name='speaker',
                                    remaps=remaps, parameters={
                                        'count': 10000, 'period': 0.05, 'prefix': 'composed'}))
        listener = graph.add(NodeSpec('listener', 'launch_fixtures.listener', remaps=remaps,
                                      parameters={'expect': 5, 'prefix': 'composed',
                                                  'timeout': 90.0}))
        graph.spin_until(lambda: listener.heard >= 5, limit_s=90.0)
        assert talker.get_fully_qualified_name() == '/speaker'
        assert talker.publisher.topic_name == '/composed/chatter'
        assert [s.topic_name for s in listener.subscriptions if 'chatter' in s.topic_name] == \
            ['/composed/chatter']
        assert (talker.get_parameter('count').value, talker.get_parameter('period').value,
                listener.get_parameter('timeout').value) == (10000, 0.05, 90.0)
        assert listener.heard >= 5


def test_a_node_class_that_takes_no_kwargs_is_refused_with_the_fix(monkeypatch, tmp_path):
    from mindgrasp_ros.errors import CompositionError

    (tmp_path / 'closed_node.py').write_text(
        'from mindgrasp_ros import rclpy\n\n\nclass Closed(rclpy.node.Node):\n'
        '    def __init__(self):\n        super().__init__("closed")\n')
    monkeypatch.syspath_prepend(str(tmp_path))
    with GraphRunner(Lockstep(0.02)) as graph, pytest.raises(
            CompositionError, match=r'closed_node.Closed cannot be composed: .*\*\*kwargs'):
        graph.add(NodeSpec('closed', 'closed_node'))
