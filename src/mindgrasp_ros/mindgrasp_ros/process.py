"""Ending a node's process promptly once the node has cleaned up.

A node stopped by SIGINT/SIGTERM cleans up in well under 0.1 s (destroy the node, shut the context
down). What takes long is the interpreter's own teardown afterwards: freeing every module of
torch, scipy and scikit-learn took 2-5 s on a loaded machine (measured: a process that only
imports torch needs 3.6 s to exit on SIGINT, with sklearn + pyRiemann 4.9 s; numpy alone 0.2 s).
That teardown has nothing left to save (files are closed, DDS entities deleted), so a node's
process ends with :func:`os._exit` right after its cleanup, as the C++ nodes of ROS 2 do with
``rclcpp::shutdown()`` and a return from ``main``.

Only the program being run is ended this way: :func:`exit_if_main_program` does nothing when the
node's ``main()`` is called from another program (a test runner, a composition).
"""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
import traceback
from collections.abc import Callable
from pathlib import Path
from types import FrameType

__all__ = ['exit_if_main_program', 'exit_process', 'handle_stop_signals',
           'interrupt_unless_importing', 'is_main_program', 'run_program']


#: set by SIGINT and SIGTERM (handle_stop_signals). A node's spin loop also checks it: the signal's
#: KeyboardInterrupt is lost when Python raises it inside a weakref callback (importlib's module
#: lock clean-up prints "Exception ignored ... KeyboardInterrupt" and drops it), which left a node
#: running after the launcher's SIGINT.
stop_requested = threading.Event()


def _interrupt(signum: int, frame: object) -> None:
    stop_requested.set()
    signal.default_int_handler(signal.SIGINT, frame)


def interrupt_unless_importing(signum: int, frame: FrameType | None) -> None:
    """A stop signal while a node program starts (:mod:`mindgrasp_ros.start`): set
    :data:`stop_requested`, and raise KeyboardInterrupt unless an import is in progress (raised
    inside a C extension's initialisation it becomes ``ImportError: initialization failed``).

    Stopped during the program's own top-level imports, nothing has run yet: the process ends
    at once with 0. Waiting for those imports to finish (torch and pyRiemann, 6 s on an idle
    2-core machine, over 10 s on a loaded one) outlasted the launcher's grace after SIGINT, and
    a node stopped before it started was reported as stopped by SIGTERM. An import inside a
    function (the program already running) is waited for, and acted on after it."""
    stop_requested.set()
    outermost_import = None
    while frame is not None:
        if frame.f_code.co_filename.startswith('<frozen importlib'):
            outermost_import = frame
        frame = frame.f_back
    if outermost_import is None:
        raise KeyboardInterrupt
    if _imports_of_the_program(outermost_import.f_back):
        exit_process(0)
    # acted on once the import is done (run_node checks stop_requested)


def _imports_of_the_program(caller: FrameType | None) -> bool:
    """True when an import was started by the program's module-level code (or by ``runpy``
    finding that module): nothing of the program has run yet."""
    if caller is None:
        return True
    name = caller.f_globals.get('__name__')
    return name == 'runpy' or (name == '__main__' and caller.f_code.co_name == '<module>')


def handle_stop_signals() -> None:
    """Ctrl-C (SIGINT) and SIGTERM raise KeyboardInterrupt in the main thread, whatever this
    process inherited, so a program stopped either way cleans up the same way; both also set
    :data:`stop_requested`.

    A process started in the background of a script (or by a test runner's worker) inherits
    SIGINT *ignored*, and Python keeps it so: such a node ignored the launcher's SIGINT until it
    was killed (its bag not closed), and an experiment ran all its trials through a Ctrl-C.
    rclpy too installs its handler whatever was inherited. Handlers the program installed
    itself are kept; nothing happens outside the main thread.
    """
    if threading.current_thread() is not threading.main_thread():
        return
    if signal.getsignal(signal.SIGINT) in (signal.SIG_IGN, signal.SIG_DFL, None,
                                           signal.default_int_handler, interrupt_unless_importing):
        signal.signal(signal.SIGINT, _interrupt)
    if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):
        signal.signal(signal.SIGTERM, _interrupt)


def is_main_program(module: str) -> bool:
    """True when ``module`` (dotted name, e.g. a node class' ``__module__``) is what this process
    runs: ``'__main__'``, ``python -m module``, or its console script (named after the module's
    last component, as ours are)."""
    if module == '__main__':
        return True
    main = sys.modules.get('__main__')
    spec = getattr(main, '__spec__', None)
    if spec is not None and spec.name == module:
        return True
    return bool(sys.argv and sys.argv[0]) and \
        Path(sys.argv[0]).stem == module.rsplit('.', 1)[-1]


def exit_if_main_program(code: int, module: str) -> None:
    """End the process now with ``code`` when ``module`` is the program being run (after flushing
    the logs and the standard streams); return otherwise."""
    if is_main_program(module):
        exit_process(code)


def exit_process(code: int | None) -> None:
    """End the process now with ``code`` (None means 0), after flushing the logs and the
    standard streams. For a node module's ``if __name__ == '__main__':`` line."""
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):   # closed or broken pipe: nothing more to say
            pass
    os._exit(0 if code is None else int(code))


def run_program(main: Callable[[], int | None]) -> None:
    """Run a node module's ``main()`` as the program and end the process right after it:
    ``if __name__ == '__main__': run_program(main)``.

    Ctrl-C or SIGTERM before the node's own handling took over (while it starts) ends it with 0,
    as a stop; any other exception is printed and ends it with 1.
    """
    try:
        code = main()
    except KeyboardInterrupt:
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        if not isinstance(exc.code, int) and exc.code is not None:
            print(exc.code, file=sys.stderr)
    except BaseException:
        traceback.print_exc()
        code = 1
    exit_process(code)
