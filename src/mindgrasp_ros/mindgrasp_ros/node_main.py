"""The one node skeleton: every node's ``main()`` is ``return run_node(NodeClass, args)``.

A node module reads like demo_nodes_py's ``talker_qos.py``::

    from mindgrasp_ros import rclpy
    from mindgrasp_ros.node_main import end_after, run_node


    class Ticker(rclpy.node.Node):
        def __init__(self, **kwargs) -> None:
            super().__init__('ticker', **kwargs)
            self.done = rclpy.task.Future()     # the node ends itself by completing this
            self.count = 0
            self.create_timer(0.1, self.timer_callback)
            end_after(self, 5.0)                # optional: end after 5 s of ROS time

        def timer_callback(self) -> None:
            self.count += 1
            if self.count == 10:                # or after a number of cycles
                self.done.set_result(0)


    def main(args: list[str] | None = None) -> int:
        return run_node(Ticker, args)

Exit codes (one convention for every node, as the launcher reports them):

- ``0`` the node finished its work (``done`` completed with ``0`` or ``None``) or was stopped
  (Ctrl-C, SIGTERM, ``rclpy.shutdown()`` from elsewhere);
- ``1`` the node failed while running: ``done`` completed with an exception (its message is printed
  as one line ``[node] ERROR: ...``) or with a non-zero exit code;
- ``2`` the node refused to start: its ``--ros-args`` are malformed (``-p bogus``, a missing or
  bad ``--params-file``), a parameter file or ``-p`` names a parameter the node does not
  declare (``lock_durtion``: :func:`~mindgrasp_ros.params.refuse_undeclared_overrides`), or its
  constructor raised a parameter error (rclpy's
  ``ParameterException`` family, :class:`~mindgrasp_ros.params.ParameterError`) or one of the
  ``errors`` the caller names (the package's own error class); one line, no traceback.

Several nodes hosted in one process (``run_composed``, lock-step) end together when one of them
ends; the process then exits 1 when any node did not end well (:func:`graph_exit_code`), and
shuts down in one order (:func:`end_graph`).

A node that must do something on the way out (stop the arm, log a count, close a bag) overrides
``destroy_node()`` and calls ``super().destroy_node()``, as in rclpy; ``rclpy.ok()`` there tells
whether it may still publish. The exit code is read after that cleanup: a node stopped by Ctrl-C
whose cleanup finds a failure (the bag could not be written) calls :func:`fail` there and exits 1.

A node with its own timing-critical thread (the bag player publishes on the bag's schedule) passes
``poll_sec``: the main thread then runs the ready callbacks without waiting in the middleware and
sleeps on ``done`` in between, so the GIL stays free for that thread.

Works with the real rclpy (``MINDGRASP_RMW=rclpy``) and with our runtime: only rclpy's public API
is used (``init``, executors, ``task.Future``, ``executors.ExternalShutdownException``).
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Callable, Sequence
from typing import Any

from mindgrasp_ros import rclpy
from mindgrasp_ros.params import refuse_undeclared_overrides
from mindgrasp_ros.process import (
    exit_if_main_program,
    handle_stop_signals,
    is_main_program,
    stop_requested,
)

__all__ = ['EXIT_FAILED', 'EXIT_OK', 'EXIT_REFUSED', 'NodeFailure', 'declare_duration',
           'end_after', 'end_graph', 'error_text', 'exit_code', 'fail', 'failure_text',
           'graph_exit_code', 'help_text', 'is_done', 'run_node']

EXIT_OK = 0       #: finished or stopped
EXIT_FAILED = 1   #: failed while running
EXIT_REFUSED = 2  #: refused to start (bad parameter or argument)


class NodeFailure(Exception):
    """The reason a node failed while running; ``fail(node, reason)`` completes ``done`` with it."""


def _parameter_errors() -> tuple[type[BaseException], ...]:
    from mindgrasp_ros.params import ParameterError

    errors: list[type[BaseException]] = [ParameterError]
    exceptions = getattr(rclpy, 'exceptions', None)
    if exceptions is None:  # pragma: no cover - real rclpy imports it lazily
        import importlib

        exceptions = importlib.import_module(f'{rclpy.__name__}.exceptions')
    errors.append(exceptions.ParameterException)
    # rclpy's InvalidParameterTypeException is not a ParameterException subclass
    for name in ('InvalidParameterTypeException', 'InvalidParameterValueException',
                 'ParameterUninitializedException'):
        cls = getattr(exceptions, name, None)
        if isinstance(cls, type):
            errors.append(cls)
    return tuple(errors)


def _argument_errors() -> tuple[type[BaseException], ...]:
    """What ``rclpy.init`` raises for a malformed ``--ros-args`` section: ours, and the real
    rclpy's ``RCLInvalidROSArgsError`` / ``UnknownROSArgsError`` when it is in use."""
    from mindgrasp_ros.runtime.arguments import RosArgumentError

    errors: list[type[BaseException]] = [RosArgumentError]
    try:
        from rclpy.impl.implementation_singleton import rclpy_implementation as impl
    except ImportError:
        return tuple(errors)
    for name in ('RCLInvalidROSArgsError', 'UnknownROSArgsError'):  # pragma: no cover - ROS 2
        cls = getattr(impl, name, None)
        if isinstance(cls, type):
            errors.append(cls)
    return tuple(errors)


def _external_shutdown() -> type[BaseException]:
    cls = getattr(rclpy.executors, 'ExternalShutdownException', None)
    return cls if isinstance(cls, type) else KeyboardInterrupt


def end_after(node: Any, duration_sec: float) -> Any:
    """Complete ``node.done`` with 0 after ``duration_sec`` s of the node's clock (ROS time; sim
    time with ``use_sim_time``); nothing when ``duration_sec`` <= 0. Returns the timer or None.

    This is the ``--number_of_cycles`` of demo_nodes_py for our nodes' ``duration`` parameter:
    launch tests and demos end by themselves.
    """
    if not duration_sec or duration_sec <= 0:
        return None
    timer = None

    def callback() -> None:
        timer.cancel()
        if not node.done.done():
            node.done.set_result(EXIT_OK)

    timer = node.create_timer(float(duration_sec), callback)
    return timer


def declare_duration(node: Any, default: float = 0.0) -> float:
    """Declare the read-only ``duration`` parameter (s; > 0 ends the node after that long of ROS
    time, for launch tests and demos) and arm :func:`end_after` with it; returns the value."""
    from mindgrasp_ros.interfaces.rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor

    desc = ParameterDescriptor(
        description='end the node after this long of ROS time; 0 runs until stopped [s]',
        additional_constraints='read-only: restart the node to change it', read_only=True,
        floating_point_range=[FloatingPointRange(from_value=0.0, to_value=float('inf'))])
    value = float(node.declare_parameter('duration', float(default), desc).value)
    end_after(node, value)
    return value


def fail(node: Any, reason: str) -> None:
    """End ``node`` with exit code 1 and ``reason`` (one line, printed by :func:`run_node`)."""
    node.get_logger().error(reason)
    if not node.done.done():
        node.done.set_exception(NodeFailure(reason))


def is_done(node: Any) -> bool:
    """True once ``node.done`` (a Future) has completed; False for a node without one. A user's
    own node in a composed launch may keep a plain ``bool`` ``done`` (as rclpy demos do); that
    counts as well."""
    done = getattr(node, 'done', None)
    if isinstance(done, bool):
        return done
    return bool(done is not None and callable(getattr(done, 'done', None)) and done.done())


def exit_code(node: Any) -> int:
    """The exit code a completed ``node.done`` stands for (0 while it runs)."""
    if not is_done(node) or isinstance(node.done, bool):
        return EXIT_OK
    if node.done.exception() is not None:
        return EXIT_FAILED
    result = node.done.result()
    return int(result) if isinstance(result, int) and not isinstance(result, bool) else EXIT_OK


def error_text(node: Any) -> str | None:
    """The failure reason of a node whose ``done`` holds an exception, else None."""
    if is_done(node) and not isinstance(node.done, bool) and node.done.exception() is not None:
        return str(node.done.exception())
    return None


def failure_text(node: Any) -> str | None:
    """Why a node that ended did not end well: its failure, or ``ended with exit code N`` for a
    node whose ``done`` holds a non-zero code (a prompter that gave up); None otherwise."""
    reason = error_text(node)
    if reason is None and exit_code(node) != EXIT_OK:
        reason = f'ended with exit code {exit_code(node)}'
    return reason


def graph_exit_code(nodes: Sequence[Any], log: Callable[[str], Any]) -> int:
    """The exit code of a graph hosted in one process (composed, lock-step): 0 when every node
    ended well or was stopped, else 1, after one ``[node] ERROR: reason`` line per node that did
    not (:func:`failure_text`), through ``log``. Read after :func:`end_graph`: a clean-up that
    failed counts too. A node alone in its process exits with its own :func:`exit_code`."""
    failed = [(node.get_name(), failure_text(node)) for node in nodes
              if failure_text(node) is not None]
    for name, reason in failed:
        log(f'[{name}] ERROR: {reason}')
    return EXIT_FAILED if failed else EXIT_OK


def end_graph(executor: Any, nodes: Sequence[Any]) -> None:
    """The shutdown order of every graph host: the executor stops first (no callback runs
    during a clean-up), then each node's ``destroy_node()``, newest first, so that a node's
    clean-up may still use the nodes created before it."""
    if executor is not None:
        executor.shutdown()
    for node in reversed(nodes):
        node.destroy_node()


#: longest single wait of a node's executor (s): how soon a signal is handled
_SIGNAL_CHECK_SEC = 0.1


def _wants_help(argv: list[str]) -> bool:
    """``-h``/``--help`` before ``--ros-args`` (after it, every word belongs to ROS)."""
    words = argv[:argv.index('--ros-args')] if '--ros-args' in argv else argv
    return any(w in ('-h', '--help') for w in words)


def help_text(node_class: Callable[[], Any]) -> str:
    """What ``<node executable> --help`` prints: the node module's docstring and the ROS
    arguments (the node does not start)."""
    module = sys.modules.get(getattr(node_class, '__module__', ''))
    doc = (getattr(module, '__doc__', None) or getattr(node_class, '__doc__', None) or '').strip()
    spec = getattr(module, '__spec__', None)          # run with -m, __name__ is '__main__'
    name = spec.name if spec is not None else getattr(module, '__name__', 'node')
    return (f'{doc}\n\n'
            f'usage: python -m {name} [--ros-args [-p NAME:=VALUE] [--params-file FILE]\n'
            '                 [-r FROM:=TO] [--log-level LEVEL]]\n'
            '       ros2 run <package> <executable> [--ros-args ...]\n\n'
            'Parameters with units, ranges and whether a change applies while the node runs:\n'
            '    mindgrasp param describe /<node> <name>   (defaults: <package>/param/*.yaml)')


def run_node(node_class: Callable[[], Any], args: list[str] | None = None, *,
             errors: tuple[type[BaseException], ...] = (), linger_sec: float = 0.0,
             poll_sec: float = 0.0) -> int:
    """Init, construct ``node_class()``, spin until Ctrl-C or ``node.done``, clean up.

    Returns the exit code (see the module docstring).

    Args:
        node_class: the Node subclass (or any factory returning a node); constructed after
            ``rclpy.init`` so it reads ``--ros-args`` parameters and remappings.
        args: command line (default ``sys.argv``), with ``--ros-args ...``.
        errors: the package's own error classes that mean "cannot start with this input" when the
            constructor raises them (exit 2, one line).
        linger_sec: after ``done`` completes, keep spinning this long (s) so reliable readers
            receive the last messages (a session's "end" prompt).
        poll_sec: 0 (default) waits for work in the middleware, as ``rclpy.spin``. > 0 polls
            instead: run what is ready without waiting, then sleep on ``done`` for up to
            ``poll_sec`` s with the GIL released. For a node whose own thread keeps a schedule
            (the bag player: its private loop did this because a blocking spin had delayed
            publications by several ms; ``benchmarks/player.py`` compares the two modes);
            callbacks (parameter services) then run up to ``poll_sec`` late.
    """
    argv = list(args if args is not None else sys.argv)
    module = getattr(node_class, '__module__', '')
    if _wants_help(argv):
        print(help_text(node_class))
        exit_if_main_program(EXIT_OK, module)
        return EXIT_OK
    label = getattr(node_class, '__name__', 'node')
    if stop_requested.is_set() and is_main_program(module):
        # Ctrl-C while the program was still importing (mindgrasp_ros.start): a stop, nothing ran
        exit_if_main_program(EXIT_OK, module)
    # before rclpy.init: the real rclpy chains its own handlers to this one, so a Ctrl-C also
    # sets stop_requested there (see the spin loop below)
    handle_stop_signals()
    try:
        rclpy.init(args=argv)
    except _argument_errors() as exc:
        print(f'[{label}] ERROR: {exc}', file=sys.stderr, flush=True)
        exit_if_main_program(EXIT_REFUSED, module)
        return EXIT_REFUSED
    node = executor = None
    try:
        try:
            node = node_class()
            # a key of a parameter file or -p that the node does not declare (a typo): refused
            refuse_undeclared_overrides(node)
        except (*_parameter_errors(), *errors) as exc:
            print(f'[{label}] ERROR: {exc}', file=sys.stderr, flush=True)
            return EXIT_REFUSED
        label = node.get_name()
        done = getattr(node, 'done', None)
        if done is None:
            done = node.done = rclpy.task.Future()
        # one executor for the node's lifetime: no add/remove per spin (rclpy.spin_once does that)
        executor = rclpy.executors.SingleThreadedExecutor()
        executor.add_node(node)
        if poll_sec > 0:
            _poll_until_done(executor, done, poll_sec)
        else:
            # waits of at most _SIGNAL_CHECK_SEC: Python runs the SIGINT handler only between
            # C calls, and a wait with nothing to wake it (a recorder whose publishers went
            # quiet) blocked Ctrl-C for good
            while not is_done(node) and rclpy.ok():
                try:
                    executor.spin_once(timeout_sec=_SIGNAL_CHECK_SEC)
                except RuntimeError:
                    # real rclpy: a SIGINT shut the context down between the wait and the take,
                    # or its KeyboardInterrupt was raised inside take_message's conversion, which
                    # pybind11 turns into 'Unable to convert call argument': a stop, not a fault
                    if rclpy.ok() and not stop_requested.is_set():
                        raise
                    break
                _raise_if_stop_requested()
        if done.done() and linger_sec > 0 and rclpy.ok():
            executor.spin_until_future_complete(rclpy.task.Future(), timeout_sec=linger_sec)
    except (KeyboardInterrupt, _external_shutdown()):
        stop_requested.clear()   # a stop: exit 0 unless the cleanup below fails the node
    finally:
        end_graph(executor, [node] if node is not None else [])
        rclpy.try_shutdown()
    # read after destroy_node(): a cleanup that failed (fail(node, ...)) counts too
    code = exit_code(node)
    reason = error_text(node)
    if reason is not None:
        print(f'[{label}] ERROR: {reason}', file=sys.stderr, flush=True)
    # run as a program: end right after the cleanup (the interpreter's teardown of torch/scipy
    # took 2-5 s on a loaded machine; a node must stop within 1 s of SIGINT)
    exit_if_main_program(code, module)
    return code


def _raise_if_stop_requested() -> None:
    """A stop signal whose KeyboardInterrupt was lost (see process.stop_requested)."""
    if stop_requested.is_set():
        raise KeyboardInterrupt


def _poll_until_done(executor: Any, done: Any, poll_sec: float) -> None:
    """Run ready callbacks without waiting in the middleware; in between, sleep on ``done`` (the
    GIL is released) for up to ``poll_sec`` s. Ends when ``done`` completes or the context shuts
    down (``rclpy.shutdown()`` from elsewhere)."""
    completed = threading.Event()
    done.add_done_callback(lambda _future: completed.set())
    while rclpy.ok() and not done.done():
        executor.spin_once(timeout_sec=0.0)
        completed.wait(poll_sec)
        _raise_if_stop_requested()
