"""In-process composition: several nodes in one process under one executor.

Messages between nodes of one process go through in-process delivery (the object is handed over,
no serialisation); DDS still carries them to other processes unless the context is DDS-less.

Node code stays unchanged: a node module is loaded by name, and the Node subclass it defines is
constructed with its own ``--ros-args`` (name, namespace, parameters, remappings), which
:class:`Component` passes through :func:`component_arguments` so that ``Node.__init__`` picks them
up without the class having to forward ``cli_args``.

Lock-step (:class:`LockstepRunner`): a DDS-less context, every node on sim time, and a runner that
owns /clock. ``step(dt)`` advances the clock and runs callbacks until the graph is quiescent, in
a fixed order, so two runs with the same seed produce the same messages.
"""

from __future__ import annotations

import contextlib
import contextvars
import importlib
import inspect
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from mindgrasp_ros.errors import RosError

__all__ = ['Component', 'CompositionError', 'LockstepRunner', 'NodeCallbackError',
           'component_arguments', 'load_node_class', 'run_composed']

_pending_args: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar(
    'mindgrasp_component_args', default=None)


class CompositionError(RosError):
    """A component could not be loaded or constructed."""


class NodeCallbackError(CompositionError):
    """A callback of a composed node raised; ``node`` names it, ``error`` is the exception."""

    def __init__(self, node: str, error: BaseException) -> None:
        self.node, self.error = node, error
        super().__init__(f'node {node!r} raised {type(error).__name__}: {error}')


def pending_component_arguments() -> list[str] | None:
    """ROS arguments set by :func:`component_arguments` for the node being constructed."""
    return _pending_args.get()


@contextlib.contextmanager
def component_arguments(args: Sequence[str]) -> Iterator[None]:
    """Nodes constructed inside this block also take ``args`` (``--ros-args ...``)."""
    token = _pending_args.set(list(args))
    try:
        yield
    finally:
        _pending_args.reset(token)


def load_node_class(module_name: str) -> type:
    """The Node subclass defined in ``module_name`` (``pkg.mod`` or ``pkg.mod:Class``)."""
    from mindgrasp_ros import rclpy

    module_name, _, class_name = module_name.partition(':')
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        msg = f'Cannot import node module {module_name!r}: {exc}'
        raise CompositionError(msg) from exc
    if class_name:
        try:
            return getattr(module, class_name)
        except AttributeError:
            msg = f'Module {module_name!r} has no class {class_name!r}.'
            raise CompositionError(msg) from None
    base = rclpy.node.Node
    classes = [obj for _n, obj in inspect.getmembers(module, inspect.isclass)
               if issubclass(obj, base) and obj is not base and obj.__module__ == module.__name__]
    if len(classes) != 1:
        names = ', '.join(c.__name__ for c in classes) or 'none'
        msg = (f'Module {module_name!r} must define exactly one Node subclass to be composed '
               f'(found: {names}); name it as "{module_name}:ClassName".')
        raise CompositionError(msg)
    return classes[0]


@dataclass
class Component:
    """A node to load: module (``pkg.mod[:Class]``) and its ROS arguments."""

    module: str
    ros_args: list[str] = field(default_factory=list)

    def create(self) -> Any:
        cls = load_node_class(self.module)
        args = list(self.ros_args)
        if args and args[0] != '--ros-args':
            args = ['--ros-args', *args]
        with component_arguments(args):
            return cls()


def run_composed(components: Sequence[Component], *, num_threads: int | None = None,
                 duration_s: float = 0.0) -> int:
    """Create every component in this process and spin them with a MultiThreadedExecutor.

    Ends on Ctrl-C, after ``duration_s`` (> 0), or when a node completes its ``done`` Future (the
    skeleton of :mod:`mindgrasp_ros.node_main`), as a launch ends when one of its processes ends.
    Returns 1 when a node failed (``done`` holds an exception), else 0.
    """
    import time

    from mindgrasp_ros import rclpy
    from mindgrasp_ros.node_main import error_text, is_done

    if not rclpy.ok():
        rclpy.init()
    nodes = []
    executor = rclpy.executors.MultiThreadedExecutor(num_threads=num_threads)
    try:
        for comp in components:
            node = comp.create()
            nodes.append(node)
            executor.add_node(node)
        deadline = time.monotonic() + duration_s if duration_s > 0 else None
        while rclpy.ok() and (deadline is None or time.monotonic() < deadline):
            executor.spin_once(timeout_sec=0.1)
            if any(is_done(node) for node in nodes):
                break
    except KeyboardInterrupt:
        pass
    finally:
        executor.shutdown()
        for node in reversed(nodes):
            node.destroy_node()
        rclpy.try_shutdown()
    failed = [(n.get_name(), error_text(n)) for n in nodes if error_text(n) is not None]
    for name, reason in failed:
        print(f'[{name}] ERROR: {reason}')
    return 1 if failed else 0


class LockstepRunner:
    """Runs nodes in one DDS-less process on a clock the caller advances.

    >>> runner = LockstepRunner()
    >>> sim = runner.add(SimNode)              # classes or Components; constructed on sim time
    >>> runner.step(1 / 240)                   # advance 1/240 s and run until quiescent
    """

    def __init__(self, *, start_time_s: float = 0.0, max_rounds: int = 1000) -> None:
        from mindgrasp_ros.runtime import context as context_mod
        from mindgrasp_ros.runtime.executors import SingleThreadedExecutor
        from mindgrasp_ros.runtime.node import Node
        from mindgrasp_ros.typesupport import get_message_class

        self.context = context_mod.Context()
        self.context.init([], transport='intra')
        self.executor = SingleThreadedExecutor(context=self.context)
        self._time_ns = round(start_time_s * 1e9)
        self._max_rounds = max_rounds
        self._clock_node = Node('lockstep_clock', context=self.context,
                                start_parameter_services=False, enable_rosout=False)
        self._clock_cls = get_message_class('rosgraph_msgs/msg/Clock')
        self._time_cls = get_message_class('builtin_interfaces/msg/Time')
        from mindgrasp_ros.runtime.qos import qos_profile_clock
        from mindgrasp_ros.topics import CLOCK

        # the runtime's own profile (the same as CLOCK's): CLOCK.qos would build the real
        # rclpy's QoSProfile under MINDGRASP_RMW=rclpy, and these nodes are the runtime's
        self._clock_pub = self._clock_node.create_publisher(self._clock_cls, CLOCK.name,
                                                            qos_profile_clock)
        self.nodes: list[Any] = []
        #: wall seconds spent in each node's callbacks (by node name), and in collecting work
        self.node_time: dict[str, float] = {}
        self.collect_time = 0.0

    @property
    def time_s(self) -> float:
        return self._time_ns / 1e9

    def add(self, node_class: type | Component, *args: Any, ros_args: Sequence[str] = (),
            **kwargs: Any) -> Any:
        """Construct a node in the lock-step context (``use_sim_time`` forced on)."""
        if isinstance(node_class, Component):
            ros_args = [*node_class.ros_args, *ros_args]
            node_class = load_node_class(node_class.module)
        extra = ['--ros-args', *[a for a in ros_args if a != '--ros-args'],
                 '-p', 'use_sim_time:=true']
        with component_arguments(extra), _default_context(self.context):
            node = node_class(*args, **kwargs)
        self._publish_clock()
        self.executor.add_node(node)
        self.nodes.append(node)
        self.spin_until_quiescent()
        return node

    def _publish_clock(self) -> None:
        sec, nsec = divmod(self._time_ns, 1_000_000_000)
        self._clock_pub.publish(self._clock_cls(clock=self._time_cls(sec=sec, nanosec=nsec)))

    def spin_until_quiescent(self) -> int:
        """Run ready callbacks until none is ready; returns how many rounds ran.

        A callback that raises ends the round with :class:`NodeCallbackError` naming its node.
        """
        rounds = 0
        clock = time.perf_counter
        times = self.node_time
        while rounds < self._max_rounds:
            t0 = clock()
            work = self._collect()
            self.collect_time += clock() - t0
            if not work:
                return rounds
            for entity, item in work:
                t0 = clock()
                try:
                    entity.execute(item)
                except (KeyboardInterrupt, SystemExit):
                    raise
                except Exception as exc:
                    raise NodeCallbackError(entity.node.get_name(), exc) from exc
                finally:
                    name = entity.node.get_name()
                    times[name] = times.get(name, 0.0) + clock() - t0
            rounds += 1
        msg = (f'The composed graph did not settle within {self._max_rounds} rounds at '
               f't={self.time_s:.6f} s: a callback keeps producing work.')
        raise CompositionError(msg)

    def _collect(self) -> list[tuple[Any, Any]]:
        """Ready work in the executor's order (timers, subscriptions, services, guards), for a
        DDS-less context run by one thread: only queues and due timers are looked at, which
        is what makes lock-step cheaper than a generic executor scan."""
        work: list[tuple[Any, Any]] = []
        for node in self.executor._nodes:
            for timer in node.timers:
                if timer._canceled:
                    continue
                now = timer.clock._override_ns
                if now is not None and timer._last_ns <= now < timer._next_ns:
                    continue                      # on sim time and not due yet
                if timer.is_ready():
                    timer._mark_called()
                    work.append((timer, None))
            # queues fill only through deliveries, which flag the node (Node.wake_executor); a
            # node nothing was delivered to since the last look is skipped
            if not node.has_work:
                continue
            node.has_work = False
            for sub in node.subscriptions:
                if sub._queue and not sub.polled:
                    work.extend((sub, item) for item in sub.take())
            for srv in node.services:
                if srv._local:
                    work.extend((srv, item) for item in srv.take())
            for client in node.clients:
                if client._reader is not None:
                    work.extend((client, item) for item in client.take())
            for guard in node.guards:
                if guard._triggered:
                    guard._triggered = False
                    work.append((guard, None))
        return work

    def step(self, dt_s: float) -> None:
        """Advance the clock by ``dt_s`` seconds and run the graph until it settles."""
        if dt_s < 0:
            msg = f'Lock-step time cannot go backwards (dt_s={dt_s}).'
            raise CompositionError(msg)
        self._time_ns += round(dt_s * 1e9)
        self._publish_clock()
        self.spin_until_quiescent()

    def close(self) -> None:
        self.executor.shutdown()
        for node in reversed(self.nodes):
            node.destroy_node()
        self._clock_node.destroy_node()
        self.context.try_shutdown()

    def __enter__(self) -> LockstepRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@contextlib.contextmanager
def _default_context(ctx: Any) -> Iterator[None]:
    """Make ``ctx`` the default context while nodes are constructed (they call Node(...))."""
    from mindgrasp_ros import runtime

    previous = runtime._default_context
    runtime._default_context = ctx
    try:
        yield
    finally:
        runtime._default_context = previous
