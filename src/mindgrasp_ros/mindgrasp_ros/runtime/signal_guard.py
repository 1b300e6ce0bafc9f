"""Signals that arrive while cyclonedds' C layer is calling Python are handled after the call.

cyclonedds-python's read and take (``ddspy_read``, ``ddspy_take``) call Python from C for every
sample: the sample info, an endpoint, its QoS. A Python signal handler runs at the next bytecode,
which can be inside one of those calls. What it raises there (a Ctrl-C's KeyboardInterrupt) is
lost as "Callfunc ... errored" or "Sampleinfo errored", ends the node with exit code 1, or makes
``ddspy_take`` crash the process (segmentation fault: an experiment stopped with Ctrl-C died
without writing its report).

:data:`DDS_CALL` guards such a call::

    with DDS_CALL:
        ret = ddspy_take(...)

Inside it, SIGINT and SIGTERM are only noted; the first one is handed to the handler in force as
soon as the outermost guarded call returns, as if it had arrived then. The handlers the program
installs (Python's KeyboardInterrupt, rclpy-style shutdown, the launcher's) are wrapped, not
replaced: :func:`signal.getsignal` returns the wrapper, whose ``inner`` is the program's handler.
``SIG_DFL``/``SIG_IGN`` and handlers installed from C are left alone (no Python runs for them).
Only the main thread runs Python signal handlers, so other threads need no guard. A guard costs
well under a microsecond: it reads the handlers with ``_signal.getsignal``, the C function behind
:func:`signal.getsignal`, whose conversion of the result to an enum took 6.5 us per read (the
guard was 10 us, called on every take: 1.7 % of a core in a live view bridge taking 1700 times a
second). ``signal.signal`` (tens of microseconds) is only called when the program installs a new
handler.
"""

from __future__ import annotations

import _signal  # the C module of signal: getsignal without the enum conversion
import signal
import threading
from types import FrameType
from typing import Any

__all__ = ['DDS_CALL']

_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_MAIN_THREAD = threading.main_thread().ident


class _Deferring:
    """A Python signal handler that defers to ``inner`` outside guarded DDS calls."""

    __slots__ = ('guard', 'inner')

    def __init__(self, guard: _DdsCallGuard, inner: Any) -> None:
        self.guard = guard
        self.inner = inner

    def __call__(self, signum: int, frame: FrameType | None) -> Any:
        if self.guard.depth:
            self.guard.pending.append(signum)
            return None
        return self.inner(signum, frame)


class _DdsCallGuard:
    """Re-entrant context manager; see the module docstring."""

    def __init__(self) -> None:
        self.depth = 0
        self.pending: list[int] = []

    def __enter__(self) -> None:
        if threading.get_ident() != _MAIN_THREAD:
            return
        for number in _SIGNALS:
            handler = _signal.getsignal(number)
            if callable(handler) and type(handler) is not _Deferring:
                signal.signal(number, _Deferring(self, handler))
        self.depth += 1

    def __exit__(self, *exc: object) -> None:
        if threading.get_ident() != _MAIN_THREAD:
            return
        self.depth -= 1
        if self.depth or not self.pending:
            return
        number = self.pending[0]
        self.pending.clear()
        handler = _signal.getsignal(number)
        if callable(handler):
            handler(number, None)       # may raise (KeyboardInterrupt): that is the point


#: the guard for cyclonedds calls that run Python callbacks from C
DDS_CALL = _DdsCallGuard()
