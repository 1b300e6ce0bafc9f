"""In-process composition: several nodes in one process under one executor.

Messages between nodes of one process go through in-process delivery (the object is handed over,
no serialisation); DDS still carries them to other processes unless the context is DDS-less.

Node code stays unchanged: a node module is loaded by name, and the Node subclass it defines is
constructed with its own ``--ros-args`` (name, namespace, remappings) and typed parameters (a
:class:`~mindgrasp_ros.node_spec.NodeSpec`), which :func:`component_arguments` hands to
``Node.__init__`` without the class having to forward ``cli_args`` or ``parameter_overrides``.
:func:`run_composed` and :class:`LockstepRunner` are the schedulers of the one graph host
(:mod:`mindgrasp_ros.graph_host`).

Lock-step (:class:`LockstepRunner`): a DDS-less context, every node on sim time, and a runner that
owns /clock. ``step(dt)`` advances the clock and runs callbacks until the graph is quiescent, in
a fixed order, so two runs with the same seed produce the same messages.
"""

from __future__ import annotations

import contextlib
import contextvars
import importlib
import inspect
from collections.abc import Iterator, Mapping, Sequence
from typing import Any

from mindgrasp_ros.errors import CompositionError, NodeCallbackError
from mindgrasp_ros.node_spec import NodeSpec

__all__ = ['CompositionError', 'LockstepRunner', 'NodeCallbackError', 'NodeSpec',
           'component_arguments', 'load_node_class', 'run_composed']

_pending: contextvars.ContextVar[tuple[list[str], dict[str, Any]] | None] = \
    contextvars.ContextVar('mindgrasp_component_args', default=None)


def pending_component_arguments() -> list[str] | None:
    """ROS arguments set by :func:`component_arguments` for the node being constructed."""
    pending = _pending.get()
    return None if pending is None else pending[0]


def pending_component_parameters() -> dict[str, Any]:
    """Typed parameter values set by :func:`component_arguments` (they win over the
    arguments' parameter files and ``-p``)."""
    pending = _pending.get()
    return {} if pending is None else pending[1]


@contextlib.contextmanager
def component_arguments(args: Sequence[str],
                        parameters: Mapping[str, Any] | None = None) -> Iterator[None]:
    """Nodes constructed inside this block also take ``args`` (``--ros-args ...``) and the
    typed ``parameters`` (as rclpy's ``parameter_overrides``)."""
    token = _pending.set((list(args), dict(parameters or {})))
    try:
        yield
    finally:
        _pending.reset(token)


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


def run_composed(specs: Sequence[NodeSpec], *, num_threads: int | None = None,
                 duration_s: float = 0.0) -> int:
    """Every node of ``specs`` in this process under one MultiThreadedExecutor
    (:class:`~mindgrasp_ros.graph_host.InProcess`), until a node ends, ``duration_s`` (> 0)
    or Ctrl-C, as a launch ends when one of its processes ends. Returns the graph's exit code
    (:func:`~mindgrasp_ros.node_main.graph_exit_code`: 1 when a node failed)."""
    from mindgrasp_ros.graph_host import GraphRunner, InProcess

    return GraphRunner(InProcess(num_threads)).run(specs, duration_s=duration_s)


class LockstepRunner:
    """Runs nodes in one DDS-less process on a clock the caller advances.

    >>> runner = LockstepRunner()
    >>> sim = runner.add(SimNode)              # classes or NodeSpecs; constructed on sim time
    >>> runner.step(1 / 240)                   # advance 1/240 s and run until quiescent
    """

    def __init__(self, *, start_time_s: float = 0.0, start_time_ns: int | None = None,
                 max_rounds: int = 1000) -> None:
        """``start_time_ns`` (ns, exactly: a bag's clock) takes the place of ``start_time_s``."""
        from mindgrasp_ros.runtime import context as context_mod
        from mindgrasp_ros.runtime.executors import LockstepExecutor
        from mindgrasp_ros.runtime.node import Node
        from mindgrasp_ros.runtime.qos import qos_profile_clock
        from mindgrasp_ros.topics import CLOCK
        from mindgrasp_ros.typesupport import get_message_class

        self.context = context_mod.Context()
        self.context.init([], transport='intra')
        self.executor = LockstepExecutor(context=self.context, max_rounds=max_rounds)
        self._time_ns = round(start_time_s * 1e9) if start_time_ns is None else int(start_time_ns)
        self._clock_node = Node('lockstep_clock', context=self.context,
                                start_parameter_services=False, enable_rosout=False)
        self._clock_cls = get_message_class('rosgraph_msgs/msg/Clock')
        self._time_cls = get_message_class('builtin_interfaces/msg/Time')
        # the runtime's own profile (the same as CLOCK's): CLOCK.qos would build the real
        # rclpy's QoSProfile under MINDGRASP_RMW=rclpy, and these nodes are the runtime's
        self._clock_pub = self._clock_node.create_publisher(self._clock_cls, CLOCK.name,
                                                            qos_profile_clock)
        self.nodes: list[Any] = []

    @property
    def time_s(self) -> float:
        return self._time_ns / 1e9

    @property
    def time_ns(self) -> int:
        """The simulated clock (ns)."""
        return self._time_ns

    @property
    def node_time(self) -> dict[str, float]:
        """Wall seconds spent in each node's callbacks, by node name."""
        return self.executor.node_time

    @property
    def collect_time(self) -> float:
        """Wall seconds the executor spent collecting ready work."""
        return self.executor.collect_time

    def add(self, node_class: type | NodeSpec, *args: Any, ros_args: Sequence[str] = (),
            parameters: Mapping[str, Any] | None = None, **kwargs: Any) -> Any:
        """Construct a node in the lock-step context (``use_sim_time`` forced on): a class
        (built with ``args``/``kwargs``) or a :class:`NodeSpec`; ``parameters`` (typed) win
        over the spec's."""
        from mindgrasp_ros.runtime import default_context

        params = dict(parameters or {})
        if isinstance(node_class, NodeSpec):
            ros_args = [*node_class.ros_arguments(), *ros_args]
            params = {**node_class.parameters, **params}
            node_class = node_class.node_class()
        params['use_sim_time'] = True
        extra = ['--ros-args', *[a for a in ros_args if a != '--ros-args']]
        with component_arguments(extra, params), default_context(self.context):
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
        try:
            return self.executor.spin_until_quiescent()
        except NodeCallbackError:
            raise
        except CompositionError as exc:
            msg = f'{exc} (at t={self.time_s:.6f} s)'
            raise CompositionError(msg) from None

    def step(self, dt_s: float) -> None:
        """Advance the clock by ``dt_s`` seconds and run the graph until it settles."""
        if dt_s < 0:
            msg = f'Lock-step time cannot go backwards (dt_s={dt_s}).'
            raise CompositionError(msg)
        self._time_ns += round(dt_s * 1e9)
        self._publish_clock()
        self.spin_until_quiescent()

    def close(self) -> None:
        from mindgrasp_ros.node_main import end_graph

        end_graph(self.executor, [self._clock_node, *self.nodes])
        self.context.try_shutdown()

    def __enter__(self) -> LockstepRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
