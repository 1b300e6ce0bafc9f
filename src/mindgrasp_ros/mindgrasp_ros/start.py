"""Start a node module as the program: ``python -m mindgrasp_ros.start MODULE [ARGS...]``.

The launcher and :class:`~mindgrasp_ros.node_process.NodeProcess` start Python nodes this way
instead of ``python -m MODULE``. The difference is Ctrl-C while the node is still importing:
a launch that ends early (a 2-trial trainer session on a busy machine) sends SIGINT to a node
that may still be importing torch or pyRiemann. Python's KeyboardInterrupt inside a C extension's
initialisation becomes ``ImportError: initialization failed`` (matplotlib's ``ft2font``, measured
in CI), the node exits 1 and the launch reports a failure although nothing had started.

Here, until the node's own signal handling takes over (:func:`~mindgrasp_ros.process.
handle_stop_signals`, called by ``run_node``), SIGINT sets
:data:`~mindgrasp_ros.process.stop_requested` and raises KeyboardInterrupt only when no import is
in progress. A stop during the module's own top-level imports ends the process at once with 0:
nothing has run yet. SIGTERM keeps its default: the launcher's escalation after a SIGINT that was
not obeyed ends the process. A stop during an import inside a function ends the node with 0 once
that import is done (:func:`~mindgrasp_ros.node_main.run_node` checks the flag first).
"""

from __future__ import annotations

import contextlib
import runpy
import signal
import sys

from mindgrasp_ros.process import exit_process, interrupt_unless_importing

__all__ = ['python_module_argv']


def python_module_argv(module: str) -> list[str]:
    """The command line that runs the Python module ``module`` as a node program."""
    return [sys.executable, '-m', 'mindgrasp_ros.start', module]


def main() -> None:
    """Run ``sys.argv[1]`` as ``__main__`` with the rest of the command line as its arguments."""
    if len(sys.argv) < 2:
        print('usage: python -m mindgrasp_ros.start MODULE [ARGS...]', file=sys.stderr)
        exit_process(2)
    # SIGINT only: SIGTERM keeps its default (the launcher's escalation ends the process)
    signal.signal(signal.SIGINT, interrupt_unless_importing)
    module = sys.argv[1]
    del sys.argv[1]    # the module sees its own argv, as under ``python -m MODULE``
    # a KeyboardInterrupt here: stopped between two imports of the module, before its main()
    with contextlib.suppress(KeyboardInterrupt):
        runpy.run_module(module, run_name='__main__', alter_sys=True)
    exit_process(0)


if __name__ == '__main__':
    main()
