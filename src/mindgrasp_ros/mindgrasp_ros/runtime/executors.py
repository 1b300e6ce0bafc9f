"""``rclpy.executors``: run the callbacks of nodes.

Each executor owns a DDS wait set (:class:`~mindgrasp_ros.runtime.dds.waitset.DdsWaitSet`:
ReadConditions of its nodes' readers plus a guard condition for in-process deliveries, timers and
shutdown) and blocks on it with the GIL released. Waits are capped at 100 ms so that Ctrl-C
(KeyboardInterrupt) is handled promptly, as Python signal handlers only run between bytecodes.
The wait names the readers that fired, and only those are taken from.
"""

from __future__ import annotations

import concurrent.futures
import os
import threading
import time
from collections.abc import Callable
from typing import Any

from mindgrasp_ros.errors import CompositionError, NodeCallbackError
from mindgrasp_ros.runtime.client import Client
from mindgrasp_ros.runtime.context import Context
from mindgrasp_ros.runtime.dds.waitset import DdsWaitSet
from mindgrasp_ros.runtime.exceptions import RCLError
from mindgrasp_ros.runtime.guard_condition import GuardCondition
from mindgrasp_ros.runtime.service import Service
from mindgrasp_ros.runtime.subscription import Subscription
from mindgrasp_ros.runtime.task import Future
from mindgrasp_ros.runtime.timer import Timer
from mindgrasp_ros.runtime.utilities import get_default_context

__all__ = [
    'Executor',
    'ExternalShutdownException',
    'LockstepExecutor',
    'MultiThreadedExecutor',
    'ShutdownException',
    'SingleThreadedExecutor',
    'TimeoutException',
]

_MAX_WAIT_S = 0.1


class ExternalShutdownException(RCLError):
    """The context was shut down while the executor was spinning."""


class ShutdownException(RCLError):
    """The executor was shut down."""


class TimeoutException(RCLError):
    """No work became ready within the timeout."""


Work = tuple[Any, Any]  # (entity, item)


class Executor:
    """Base executor: collects ready work from its nodes and runs it."""

    def __init__(self, *, context: Context | None = None) -> None:
        self._context = context or get_default_context()
        self._nodes: list[Any] = []
        self._lock = threading.RLock()
        self._is_shutdown = False
        self._generation = -1
        self._cond = threading.Condition()
        self._woken = False
        self._waitset: DdsWaitSet | None = None
        self._ready: set[int] | None = None         # ids of readers the last wait saw fire
        self._pending: list[Work] = []
        self._waiting = False
        dds = self._context.dds
        if dds is not None:
            self._waitset = DdsWaitSet(dds)

    @property
    def context(self) -> Context:
        return self._context

    # ------------------------------------------------------------------ nodes
    def add_node(self, node: Any) -> bool:
        with self._lock:
            if node in self._nodes:
                return False
            if node.executor is not None and node.executor is not self:
                node.executor.remove_node(node)
            self._nodes.append(node)
            node.executor = self
            self._generation = -1
        self._wake_if_waiting()
        return True

    def remove_node(self, node: Any) -> None:
        with self._lock:
            if node in self._nodes:
                self._nodes.remove(node)
                if node.executor is self:
                    node.executor = None
                self._generation = -1
        self._wake_if_waiting()

    def _wake_if_waiting(self) -> None:
        # Only a wait in another thread needs waking to see the change. Waking always would
        # make rclpy.spin_once(node) (add, spin, remove) return at once every time: a busy loop.
        if self._waiting:
            self.wake()

    def get_nodes(self) -> list[Any]:
        with self._lock:
            return list(self._nodes)

    def wake(self) -> None:
        if self._woken:
            # A wake is pending: whoever waits next returns at once and collects this work with
            # the rest (it was queued before this check). Lock-step never waits, so this skips
            # a lock and a notify per delivered message.
            return
        with self._cond:
            self._woken = True
            self._cond.notify_all()
        if self._waitset is not None:
            self._waitset.trigger()

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        self._is_shutdown = True
        self.wake()
        with self._lock:
            for node in list(self._nodes):
                if node.executor is self:
                    node.executor = None
            self._nodes.clear()
        self._release_waitset()
        return True

    def _release_waitset(self) -> None:
        if self._waitset is not None and self._context.dds is not None:
            self._waitset.release()

    # ------------------------------------------------------------------ waiting
    def _sync_conditions(self) -> bool:
        """Attach ReadConditions for the readers of our nodes (when entities changed); True when
        they changed."""
        generation = sum(n.generation for n in self._nodes) + 1000003 * len(self._nodes)
        if generation == self._generation or self._waitset is None:
            return False
        self._generation = generation
        wanted: dict[int, Any] = {}
        for node in self._nodes:
            for entity in (*node.subscriptions, *node.services, *node.clients):
                reader = entity.dds_reader
                if reader is not None and not entity.polled:
                    wanted[id(reader)] = reader
        self._waitset.watch(wanted)
        return True

    def _timeout_for_timers(self, timeout_sec: float | None) -> float | None:
        wait = timeout_sec
        for node in self._nodes:
            for timer in node.timers:
                ns = timer.time_until_next_call()
                if ns is None:
                    continue
                if timer.clock.ros_time_is_active:
                    continue  # sim time advances with /clock messages, which wake us
                s = ns / 1e9
                wait = s if wait is None else min(wait, s)
        return wait

    def _triggered(self, timeout_ns: int) -> set[int] | None:
        """Wait up to ``timeout_ns`` (0: just look) on the WaitSet; the ids of the readers whose
        ReadCondition fired (None when it cannot tell: every reader is then taken from)."""
        if self._waitset is None or self._context.dds is None:
            return None
        return self._waitset.wait(timeout_ns)

    def _wait(self, timeout_sec: float | None) -> None:
        self._ready = None
        timeout = _MAX_WAIT_S if timeout_sec is None else min(timeout_sec, _MAX_WAIT_S)
        if timeout <= 0:
            return
        with self._cond:
            if self._woken:
                self._woken = False
                return
            self._waiting = True
        try:
            self._wait_blocking(timeout)
        finally:
            self._waiting = False

    def _wait_blocking(self, timeout: float) -> None:
        if self._waitset is not None and self._context.dds is not None:
            self._ready = self._triggered(int(timeout * 1e9))
            self._waitset.clear_trigger()
            with self._cond:
                self._woken = False
        else:
            with self._cond:
                if not self._woken:
                    self._cond.wait(timeout)
                self._woken = False

    # ------------------------------------------------------------------ work
    def _collect(self, ready: set[int] | None = None) -> list[Work]:
        """Ready work, in a fixed order: timers, subscriptions, services, clients, guards.
        ``ready``: ids of the DDS readers with data (None: try every reader); in-process
        deliveries are always taken."""
        work: list[Work] = []
        for node in list(self._nodes):
            for timer in list(node.timers):
                if not timer.busy and timer.callback_group.can_execute(timer) and \
                        timer.is_ready():
                    timer.call_timer()
                    work.append((timer, None))
            for entity in (*node.subscriptions, *node.services, *node.clients):
                if entity.busy or entity.polled:
                    continue
                dds = ready is None or id(entity.dds_reader) in ready
                if isinstance(entity, Client):
                    # replies complete futures; never hold them back behind a busy group
                    work.extend((entity, item) for item in entity.take(dds))
                    continue
                if not entity.callback_group.can_execute(entity):
                    continue
                work.extend((entity, item) for item in entity.take(dds))
            for guard in list(node.guards):
                if guard.has_data_hint() and guard.callback_group.can_execute(guard):
                    work.extend((guard, item) for item in guard.take())
        return work

    def _run(self, entity: Any, item: Any) -> None:
        try:
            entity.execute(item)
        except (KeyboardInterrupt, SystemExit):
            raise
        except ExternalShutdownException:
            raise
        except Exception:
            node = entity.node
            if isinstance(entity, (Subscription, Timer, Service, GuardCondition)) and \
                    not self._context.ok():
                return
            node.get_logger().error(
                f'Uncaught exception in a callback of {type(entity).__name__} '
                f"'{getattr(entity, 'topic_name', getattr(entity, 'srv_name', ''))}'.")
            raise

    def _spin_once_impl(self, timeout_sec: float | None) -> bool:
        """Wait for and execute work; True if something ran."""
        if not self._context.ok():
            raise ExternalShutdownException()
        if self._is_shutdown:
            raise ShutdownException()
        with self._lock:
            self._sync_conditions()
            if not self._pending:
                self._pending = self._collect(self._triggered(0))
            has_work = bool(self._pending)
            wait_s = None if has_work else self._timeout_for_timers(timeout_sec)
        if not has_work:
            self._wait(wait_s)
            if not self._context.ok():
                raise ExternalShutdownException()
            with self._lock:
                ready, self._ready = self._ready, None
                if self._sync_conditions():   # new readers: the wait did not watch them
                    ready = None
                self._pending = self._collect(ready)
                if not self._pending:
                    return False
        ran = self._dispatch()
        if not ran:  # everything ready belongs to busy callback groups: wait for a worker
            self._wait(_MAX_WAIT_S if timeout_sec is None else min(timeout_sec, _MAX_WAIT_S))
        return ran

    def _dispatch(self) -> bool:
        raise NotImplementedError

    # ------------------------------------------------------------------ public API
    def spin(self) -> None:
        while self._context.ok() and not self._is_shutdown:
            self.spin_once()

    def spin_once(self, timeout_sec: float | None = None) -> None:
        try:
            self._spin_once_impl(timeout_sec)
        except ShutdownException:
            pass

    def spin_until_future_complete(self, future: Future, timeout_sec: float | None = None) -> None:
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        future.add_done_callback(lambda _f: self.wake())
        while self._context.ok() and not future.done() and not self._is_shutdown:
            remaining = None if deadline is None else deadline - time.monotonic()
            if remaining is not None and remaining <= 0:
                return
            self.spin_once(remaining)

    def spin_once_until_future_complete(self, future: Future,
                                        timeout_sec: float | None = None) -> None:
        future.add_done_callback(lambda _f: self.wake())
        self.spin_once(timeout_sec)

    def create_task(self, callback: Callable, *args: Any) -> Future:
        future = Future()
        try:
            future.set_result(callback(*args))
        except Exception as exc:
            future.set_exception(exc)
        return future

    def __enter__(self) -> Executor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()


class SingleThreadedExecutor(Executor):
    """Runs every callback in the thread that spins."""

    def _dispatch(self) -> bool:
        with self._lock:
            work, self._pending = self._pending, []
        for entity, item in work:
            self._run(entity, item)
        return bool(work)


class MultiThreadedExecutor(Executor):
    """Runs callbacks in a thread pool; callback groups decide what may run concurrently."""

    def __init__(self, num_threads: int | None = None, *, context: Context | None = None) -> None:
        super().__init__(context=context)
        self._pool = concurrent.futures.ThreadPoolExecutor(
            max_workers=num_threads or max(2, os.cpu_count() or 2),
            thread_name_prefix='mindgrasp_executor')
        self._errors: list[BaseException] = []

    def _dispatch(self) -> bool:
        with self._lock:
            pending, self._pending = self._pending, []
        batches: dict[int, list[Work]] = {}
        ran = False
        for entity, item in pending:
            batches.setdefault(id(entity), []).append((entity, item))
        for batch in batches.values():
            entity = batch[0][0]
            group = entity.callback_group
            if not isinstance(entity, Client) and not group.beginning_execution(entity):
                with self._lock:
                    self._pending.extend(batch)  # its group is busy: try again next round
                continue
            entity.busy = True
            self._pool.submit(self._run_batch, batch)
            ran = True
        if self._errors:
            raise self._errors.pop(0)
        return ran

    def _run_batch(self, batch: list[Work]) -> None:
        entity = batch[0][0]
        try:
            for _entity, item in batch:
                self._run(entity, item)
        except BaseException as exc:
            self._errors.append(exc)
        finally:
            entity.busy = False
            if not isinstance(entity, Client):
                entity.callback_group.ending_execution(entity)
            self.wake()

    def shutdown(self, timeout_sec: float | None = None) -> bool:
        super().shutdown(timeout_sec)
        self._pool.shutdown(wait=True, cancel_futures=True)
        return True


class LockstepExecutor(Executor):
    """Runs ready callbacks until none is left, in the calling thread and a fixed order, for a
    DDS-less context on a clock that only its owner advances (lock-step:
    :class:`~mindgrasp_ros.graph.lockstep.LockstepRunner` steps the clock, then calls
    :meth:`spin_until_quiescent`).

    It never waits: nothing arrives from outside the process, and time moves only between
    steps. Readiness comes from the entities' own API, as rclpy's executors take it from the
    wait set: ``Timer.is_ready``/``call_timer``, and ``has_data_hint``/``take`` of
    subscriptions, services, clients and guard conditions. The entities looked at are those the
    node reports as given work since the last round (``Node.take_ready_entities``, fed by
    ``Node.wake_executor``), as a wait set reports what fired: most nodes get nothing in most
    rounds, which is what makes lock-step cheaper than a generic scan.
    """

    def __init__(self, *, context: Context | None = None, max_rounds: int = 1000) -> None:
        super().__init__(context=context)
        self.max_rounds = max_rounds
        #: wall seconds spent in each node's callbacks (by node name), and in collecting work
        self.node_time: dict[str, float] = {}
        self.collect_time = 0.0

    def spin_until_quiescent(self) -> int:
        """Run ready callbacks until none is ready; returns how many rounds ran.

        A callback that raises ends the round with :class:`NodeCallbackError` naming its node;
        a graph still busy after ``max_rounds`` rounds raises :class:`CompositionError`.
        """
        rounds = 0
        clock = time.perf_counter
        times = self.node_time
        while rounds < self.max_rounds:
            t0 = clock()
            work = self._collect_ready()
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
        msg = (f'The composed graph did not settle within {self.max_rounds} rounds: a callback '
               'keeps producing work.')
        raise CompositionError(msg)

    def _spin_once_impl(self, timeout_sec: float | None) -> bool:
        """One round of the ready work, without waiting (``spin_once`` of rclpy's API)."""
        if not self._context.ok():
            raise ExternalShutdownException()
        if self._is_shutdown:
            raise ShutdownException()
        self._pending = self._collect_ready()
        return self._dispatch()

    def _dispatch(self) -> bool:
        work, self._pending = self._pending, []
        for entity, item in work:
            self._run(entity, item)
        return bool(work)

    def _collect_ready(self) -> list[Work]:
        """Ready work in the executor's order: timers, then subscriptions, services, clients
        and guard conditions of each node. Not an override of :meth:`Executor._collect`: there
        is no wait set, each node names the entities given work (``take_ready_entities``)."""
        work: list[Work] = []
        for node in self._nodes:
            for timer in node.timers:
                if timer.is_ready():
                    timer.call_timer()
                    work.append((timer, None))
            ready = node.take_ready_entities()
            if ready is None:   # entities changed: look at every one
                ready = [*node.subscriptions, *node.services, *node.clients, *node.guards]
            for entity in ready:
                if entity.has_data_hint() and not entity.polled:
                    work.extend((entity, item) for item in entity.take())
        return work
