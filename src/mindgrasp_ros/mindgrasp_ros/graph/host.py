"""One graph host: a graph's nodes (:class:`~mindgrasp_ros.graph.spec.NodeSpec`) run by one
runner under an interchangeable scheduler.

    from mindgrasp_ros.graph import GraphRunner, InProcess, Lockstep, Processes

    code = GraphRunner(Lockstep(step_s=0.02)).run(specs, duration_s=60.0)   # simulated time
    code = GraphRunner(InProcess()).run(specs)                              # one process
    code = GraphRunner(Processes(run_dir)).run(specs)                       # a process each

Whatever the scheduler, a graph ends in one way: when one of its nodes ends
(:func:`~mindgrasp_ros.node_main.is_done`; for a node in its own process, when the process
exits), after ``duration_s`` on the scheduler's clock, on a caller's condition, or on Ctrl-C. It
then shuts down in one order (:func:`~mindgrasp_ros.node_main.end_graph`: the scheduler stops,
the nodes are destroyed newest first) and its exit code is
:func:`~mindgrasp_ros.node_main.graph_exit_code` (1 when a node failed, raised in a callback or
ended with a non-zero code, with one ``[node] ERROR: ...`` line each, else 0).

The ``--composed`` container (:func:`run_composed`), ``mindgrasp launch --lockstep``
(``run_lockstep``), the experiment engine (``run_trial``) and replay call this runner; the
scheduler and what they wait for are all that differs between them. A scheduler that builds a
node in its own process passes the spec's arguments to the node class as rclpy's ``Node`` takes
them (``cli_args``, ``parameter_overrides``): the same under our runtime and the real rclpy.
"""

from __future__ import annotations

import concurrent.futures
import math
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any, Protocol

from mindgrasp_ros.errors import CompositionError, NodeCallbackError
from mindgrasp_ros.graph.loader import check_composable, load_node_class
from mindgrasp_ros.graph.spec import NodeSpec

__all__ = ['GraphRunner', 'InProcess', 'Lockstep', 'ProcessHandle', 'Processes', 'Scheduler',
           'run_composed']


class Scheduler(Protocol):
    """How a graph's nodes are hosted and given time (one of :class:`Lockstep`,
    :class:`InProcess`, :class:`Processes`)."""

    def add(self, spec: NodeSpec) -> Any:
        """Start the node of ``spec``; return it (or a handle with ``get_name()`` and ``done``)."""

    def spin_once(self) -> None:
        """Give the graph one unit of time (a lock-step step, an executor wait, a poll)."""

    @property
    def time_s(self) -> float:
        """The scheduler's clock (s): simulated time in lock-step, else wall time since start."""

    def ok(self) -> bool:
        """False once the graph was shut down from elsewhere (``rclpy.shutdown()``)."""

    def close(self, nodes: Sequence[Any]) -> None:
        """Stop the scheduler, then destroy ``nodes`` newest first (:func:`end_graph`)."""


class GraphRunner:
    """Runs a graph of :class:`NodeSpec` under a :class:`Scheduler`.

    ``run(specs)`` is the whole lifecycle; a caller that drives the graph itself (the experiment
    engine waits for its trial manager; replay feeds recorded messages) uses :meth:`add`,
    :meth:`spin_until` and :meth:`close` (or ``with GraphRunner(...) as runner``).
    """

    def __init__(self, scheduler: Scheduler, *, log: Callable[[str], Any] = print) -> None:
        self.scheduler = scheduler
        self.log = log
        self.nodes: list[Any] = []
        self.interrupted = False   #: Ctrl-C ended :meth:`run` (its caller may stop too)
        self._closed = False

    def add(self, spec: NodeSpec) -> Any:
        """Start one node; returns it."""
        node = self.scheduler.add(spec)
        self.nodes.append(node)
        return node

    def ended(self) -> bool:
        """A node ended (:func:`~mindgrasp_ros.node_main.is_done`), or the graph was shut down."""
        from mindgrasp_ros.node_main import is_done

        return not self.scheduler.ok() or any(is_done(node) for node in self.nodes)

    def spin_until(self, condition: Callable[[], bool], limit_s: float = math.inf) -> None:
        """Spin until ``condition()`` or ``limit_s`` seconds on the scheduler's clock."""
        end = self.scheduler.time_s + limit_s
        while not condition() and self.scheduler.time_s < end:
            self.scheduler.spin_once()

    def run(self, specs: Iterable[NodeSpec] = (), *, duration_s: float = 0.0) -> int:
        """Start ``specs``, spin until a node ends, ``duration_s`` (> 0) or Ctrl-C; close.

        Returns the graph's exit code (:func:`~mindgrasp_ros.node_main.graph_exit_code`); a
        callback that raised (lock-step) counts as its node failing.
        """
        from mindgrasp_ros.node_main import EXIT_FAILED, graph_exit_code

        raised = False
        try:
            for spec in specs:
                self.add(spec)
            self.spin_until(self.ended, duration_s if duration_s > 0 else math.inf)
        except NodeCallbackError as exc:
            self.log(f'[{exc.node}] ERROR: {type(exc.error).__name__}: {exc.error}')
            raised = True
        except KeyboardInterrupt:
            self.interrupted = True
        finally:
            self.close()
        code = graph_exit_code(self.nodes, self.log)
        return EXIT_FAILED if raised else code

    def close(self) -> None:
        """Stop the scheduler and destroy the nodes, newest first (once)."""
        if not self._closed:
            self._closed = True
            self.scheduler.close(self.nodes)

    def __enter__(self) -> GraphRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class Lockstep:
    """Every node in this process, DDS-less, on a simulated clock advanced ``step_s`` at a time
    (:class:`~mindgrasp_ros.graph.lockstep.LockstepRunner`): the same seed gives the same messages
    in the same order whatever the machine's load."""

    def __init__(self, step_s: float = 0.02, *, start_time_ns: int = 0) -> None:
        from mindgrasp_ros.graph.lockstep import LockstepRunner

        self.step_s = step_s
        self.runner = LockstepRunner(start_time_ns=start_time_ns)

    def add(self, spec: NodeSpec) -> Any:
        return self.runner.add(spec)

    def spin_once(self) -> None:
        self.runner.step(self.step_s)

    @property
    def time_s(self) -> float:
        return self.runner.time_s

    def ok(self) -> bool:
        return True

    def close(self, nodes: Sequence[Any]) -> None:
        self.runner.close()   # the runner's clock node and every node it built, newest first


class InProcess:
    """Every node in this process under one ``MultiThreadedExecutor``, on wall time; messages
    between them are handed over without serialisation, DDS carries them to other processes."""

    def __init__(self, num_threads: int | None = None) -> None:
        from mindgrasp_ros import rclpy

        if not rclpy.ok():
            rclpy.init()
        self.executor = rclpy.executors.MultiThreadedExecutor(num_threads=num_threads)
        self._t0 = time.monotonic()

    def add(self, spec: NodeSpec) -> Any:
        from mindgrasp_ros import rclpy

        node_class = spec.node_class()
        check_composable(node_class, ('cli_args', 'parameter_overrides'))
        node = node_class(**spec.node_arguments(rclpy.parameter.Parameter))
        self.executor.add_node(node)
        return node

    def spin_once(self) -> None:
        self.executor.spin_once(timeout_sec=0.1)

    @property
    def time_s(self) -> float:
        return time.monotonic() - self._t0

    def ok(self) -> bool:
        from mindgrasp_ros import rclpy

        return rclpy.ok()

    def close(self, nodes: Sequence[Any]) -> None:
        from mindgrasp_ros import rclpy
        from mindgrasp_ros.node_main import end_graph

        end_graph(self.executor, nodes)
        rclpy.try_shutdown()


class _ProcessNode:
    """A node in its own process, as a graph host sees a node: ``get_name()`` and a ``done``
    future that completes with the process's exit code when it exits."""

    def __init__(self, label: str, process: Any) -> None:
        self.label = label
        self.process = process
        self.done: concurrent.futures.Future[int] = concurrent.futures.Future()

    def get_name(self) -> str:
        return self.label

    def poll(self) -> None:
        code = self.process.poll()
        if code is not None and not self.done.done():
            self.done.set_result(code)

    def destroy_node(self) -> None:
        """Stop the process as the launcher does (SIGINT, SIGTERM, SIGKILL)."""
        code = self.process.stop()
        if not self.done.done():
            self.done.set_result(code)


class ProcessHandle(Protocol):
    """A process a caller builds itself (a launch's process: its own command line, output and
    respawn policy), hosted by :class:`Processes` as it hosts a node's process."""

    done: concurrent.futures.Future[int]   #: completes with the exit code once it ended for good

    def get_name(self) -> str:
        """The label of the process."""

    def start(self) -> None:
        """Start the process."""

    def poll(self) -> None:
        """Look whether the process ended (and set :attr:`done`, or restart it)."""

    def destroy_node(self) -> None:
        """Stop the process (SIGINT, then SIGTERM, then SIGKILL) unless it ended already."""


class Processes:
    """Each node in a process of its own (``python -m <module> --ros-args ...``), over DDS, its
    output in ``run_dir/<label>.log`` and its parameters in ``run_dir/params/<label>.yaml``;
    ``env``: the processes' environment (None: this one's). A node given as ``pkg.mod:Class``
    runs under :func:`main` of this module. :meth:`add` also takes a :class:`ProcessHandle`
    (the launcher's processes), polled and stopped in the same order."""

    POLL_S = 0.05   #: how often (s) the host looks for a process that ended

    def __init__(self, run_dir: str | Path, *, env: dict[str, str] | None = None) -> None:
        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.env = env
        self._handles: list[Any] = []
        self._t0 = time.monotonic()

    def add(self, spec: NodeSpec | ProcessHandle) -> Any:
        from mindgrasp_ros.node_process import NodeProcess

        if not isinstance(spec, NodeSpec):   # a process the caller built: it starts itself
            self._handles.append(spec)
            spec.start()
            return spec
        args = spec.process_arguments(self.run_dir / 'params')
        module, args = ((__name__, [spec.module, *args]) if ':' in spec.module
                        else (spec.module, args))
        handle = _ProcessNode(spec.label, NodeProcess(module, args, self.env,
                                                      self.run_dir / f'{spec.label}.log'))
        self._handles.append(handle)
        return handle

    def spin_once(self) -> None:
        # a supervisor's poll: the processes run by themselves, the host only looks for an end
        time.sleep(self.POLL_S)
        for handle in self._handles:
            handle.poll()

    @property
    def time_s(self) -> float:
        return time.monotonic() - self._t0

    def ok(self) -> bool:
        return True

    def close(self, nodes: Sequence[Any]) -> None:
        from mindgrasp_ros.node_main import end_graph

        end_graph(None, nodes)


def run_composed(specs: Sequence[NodeSpec], *, num_threads: int | None = None,
                 duration_s: float = 0.0) -> int:
    """Every node of ``specs`` in this process under one MultiThreadedExecutor
    (:class:`InProcess`), until a node ends, ``duration_s`` (> 0) or Ctrl-C, as a launch ends
    when one of its processes ends. Returns the graph's exit code
    (:func:`~mindgrasp_ros.node_main.graph_exit_code`: 1 when a node failed)."""
    return GraphRunner(InProcess(num_threads)).run(specs, duration_s=duration_s)


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m mindgrasp_ros.graph.host pkg.mod:Class [--ros-args ...]``: one node class
    under :func:`~mindgrasp_ros.node_main.run_node` (a module's own ``main()`` otherwise)."""
    from mindgrasp_ros.node_main import EXIT_REFUSED, run_node

    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv:
        print('usage: python -m mindgrasp_ros.graph.host pkg.mod[:Class] [--ros-args ...]',
              file=sys.stderr)
        return EXIT_REFUSED
    try:
        node_class = load_node_class(argv[0])
    except CompositionError as exc:
        print(exc, file=sys.stderr)
        return EXIT_REFUSED
    return run_node(node_class, argv[1:])


if __name__ == '__main__':
    sys.exit(main())
