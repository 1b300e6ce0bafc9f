"""``python -m mindgrasp_ros.start MODULE``: a node stopped while it still imports ends with 0.

A launch that ends early sends SIGINT to nodes that may still be importing torch or pyRiemann;
a KeyboardInterrupt inside a C extension's initialisation became ``ImportError: initialization
failed`` and exit 1 (CI). Waiting for the imports instead outlasted the launcher's 10 s grace on a
loaded machine (the classifier, stopped by SIGTERM). Here the node module's import takes 300 s,
so the signal arrives during an import every time, and the node must end long before it is done.
"""

from __future__ import annotations

import os
import signal
import textwrap
import time
from pathlib import Path

from mindgrasp_ros.node_process import NodeProcess

DEPENDENCY = '''
import time
from pathlib import Path

Path(__file__).with_name('importing').touch()
deadline = time.monotonic() + 300.0
while time.monotonic() < deadline:      # an import as slow as torch on a machine at a standstill
    time.sleep(0.01)
'''

NODE = '''
import slow_dependency  # noqa: F401  (300 s in its import)
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import run_node


class Never(rclpy.node.Node):
    def __init__(self) -> None:
        print('constructed', flush=True)
        super().__init__('never')


def main() -> int:
    return run_node(Never, [])


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)
'''


def _stop_while_importing(tmp_path: Path, dependency: str, node: str,
                          wait_s: float) -> tuple[int, str]:
    """Start ``node`` (importing ``dependency``), send SIGINT once the import began, and return
    the exit code (within ``wait_s``) and the output."""
    (tmp_path / 'slow_dependency.py').write_text(textwrap.dedent(dependency))
    (tmp_path / 'slow_node.py').write_text(textwrap.dedent(node))
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(
        [str(tmp_path), os.environ.get('PYTHONPATH', '')])}
    proc = NodeProcess('slow_node', [], env, tmp_path / 'node.log')
    try:
        deadline = time.monotonic() + 300.0
        while not (tmp_path / 'importing').exists():
            assert proc.poll() is None, proc.output()
            assert time.monotonic() < deadline, proc.output()
            time.sleep(0.05)
        proc.proc.send_signal(signal.SIGINT)
        code = proc.wait(wait_s)
    finally:
        proc.stop()
    return code, proc.output()


def test_a_node_stopped_while_importing_ends_with_0_and_never_starts(tmp_path: Path) -> None:
    # at once; an import done first would take 300 s
    code, out = _stop_while_importing(tmp_path, DEPENDENCY, NODE, 120.0)
    assert code == 0, out
    assert 'constructed' not in out and 'Traceback' not in out, out


WAITING_DEPENDENCY = '''
import time
from pathlib import Path

from mindgrasp_ros.process import stop_requested

Path(__file__).with_name('importing').touch()
deadline = time.monotonic() + 300.0
while not stop_requested.is_set() and time.monotonic() < deadline:   # the test's SIGINT
    time.sleep(0.01)
print('imported', flush=True)
'''

LAZY_NODE = NODE.replace(
    'import slow_dependency  # noqa: F401  (300 s in its import)\n', '').replace(
    'def main() -> int:\n', 'def main() -> int:\n    import slow_dependency  # noqa: F401\n')


def test_a_stop_during_an_import_inside_main_is_acted_on_after_it(tmp_path: Path) -> None:
    """The program already runs (an import inside a function): the import is not broken off,
    and the node ends with 0 right after it, before it is constructed."""
    code, out = _stop_while_importing(tmp_path, WAITING_DEPENDENCY, LAZY_NODE, 300.0)
    assert code == 0 and 'imported' in out, out
    assert 'constructed' not in out and 'Traceback' not in out, out
