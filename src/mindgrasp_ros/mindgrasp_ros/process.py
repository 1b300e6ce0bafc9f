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
import sys
from pathlib import Path

__all__ = ['exit_if_main_program', 'is_main_program']


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
    if not is_main_program(module):
        return
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):   # closed or broken pipe: nothing more to say
            pass
    os._exit(code)
