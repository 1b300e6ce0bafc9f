"""Lock-step: every node of a graph in one DDS-less process, on a clock the caller advances.

Every node runs on sim time, and a runner owns /clock: ``step(dt)`` advances the clock and runs
callbacks until the graph is quiescent, in a fixed order, so two runs with the same seed produce
the same messages. Messages between the nodes are handed over without serialisation.

A node is constructed with its arguments, as rclpy's ``Node`` takes them: ``context`` (the
runner's), ``cli_args`` (name, remaps, further ROS arguments) and typed ``parameter_overrides``
(:meth:`~mindgrasp_ros.graph.spec.NodeSpec.node_arguments`); its class forwards ``**kwargs`` to
``Node.__init__`` (:mod:`mindgrasp_ros.graph.loader`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from mindgrasp_ros.errors import CompositionError, NodeCallbackError
from mindgrasp_ros.graph.loader import check_composable
from mindgrasp_ros.graph.spec import NodeSpec
from mindgrasp_ros.node_main import end_graph
from mindgrasp_ros.runtime.context import Context
from mindgrasp_ros.runtime.executors import LockstepExecutor
from mindgrasp_ros.runtime.node import Node
from mindgrasp_ros.runtime.parameter import Parameter
from mindgrasp_ros.runtime.qos import qos_profile_clock
from mindgrasp_ros.topics import CLOCK
from mindgrasp_ros.typesupport import get_message_class

__all__ = ['LockstepRunner']

#: what the runner passes to every node class it constructs
NODE_KEYWORDS = ('context', 'cli_args', 'parameter_overrides')


class LockstepRunner:
    """Runs nodes in one DDS-less process on a clock the caller advances.

    >>> runner = LockstepRunner()
    >>> sim = runner.add(SimNode)              # classes or NodeSpecs; constructed on sim time
    >>> runner.step(1 / 240)                   # advance 1/240 s and run until quiescent
    """

    def __init__(self, *, start_time_s: float = 0.0, start_time_ns: int | None = None,
                 max_rounds: int = 1000) -> None:
        """``start_time_ns`` (ns, exactly: a bag's clock) takes the place of ``start_time_s``."""
        self.context = Context()
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
        """Construct a node in the lock-step context (``use_sim_time`` forced on).

        Parameters
        ----------
        node_class : type or NodeSpec
            A Node subclass (built with ``args`` and ``kwargs``) or a :class:`NodeSpec`.
        ros_args : sequence of str
            ROS arguments after the spec's (``-p name:=value``, ``-r from:=to``).
        parameters : mapping of str to object, optional
            Typed parameter values; they win over the spec's and over ``ros_args``.

        Returns
        -------
        Node
            The node, added to the runner's executor after the graph settled.
        """
        extra = [a for a in ros_args if a != '--ros-args']
        params = {**(parameters or {}), 'use_sim_time': True}
        if isinstance(node_class, NodeSpec):
            node_args = node_class.node_arguments(Parameter, params)
            node_args['cli_args'] += extra
            node_class = node_class.node_class()
        else:
            node_args = {'cli_args': ['--ros-args', *extra],
                         'parameter_overrides': [Parameter(name, value=value)
                                                 for name, value in params.items()]}
        check_composable(node_class, NODE_KEYWORDS)
        node = node_class(*args, **kwargs, context=self.context, **node_args)
        self.nodes.append(node)    # first: a Ctrl-C from here on still destroys it (closes its bag)
        self._publish_clock()
        self.executor.add_node(node)
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
        end_graph(self.executor, [self._clock_node, *self.nodes])
        self.context.try_shutdown()

    def __enter__(self) -> LockstepRunner:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
