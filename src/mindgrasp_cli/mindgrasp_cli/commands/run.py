"""Run a node of a package, like ``ros2 run <package> <executable> [args]``.

    mindgrasp run mindgrasp_trainer graz_node --ros-args -p n_trials:=2
    mindgrasp run mindgrasp_sim sim_node --ros-args -p gui:=true

The executable resolves as in launch files: the package's node module (``python -m``), else
``lib/<package>/<executable>`` of a sourced ROS 2 workspace, else a program on PATH. Arguments
after the executable go to the node unchanged; its exit code is this command's.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from mindgrasp_launch.actions.node import find_module, resolve_program


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('package', help='ROS package name, e.g. mindgrasp_fsm')
    parser.add_argument('executable', help='executable of the package, e.g. fsm_node')
    parser.add_argument('argv', nargs=argparse.REMAINDER,
                        help='arguments of the node (e.g. --ros-args -p name:=value)')


def _package_exists(package: str) -> bool:
    """``package`` is one of our Python packages or in a sourced ROS 2 workspace's index."""
    if find_module(package):
        return True
    return any(Path(prefix, 'share', 'ament_index', 'resource_index', 'packages', package).is_file()
               for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep) if prefix)


def main(args: argparse.Namespace) -> int:
    if not _package_exists(args.package):
        # as ros2 run: without this, any program on PATH named like the executable ran
        print(f"mindgrasp run: error: package '{args.package}' not found; check the name (our "
              "packages are mindgrasp_*) or source the ROS 2 workspace that has it.",
              file=sys.stderr)
        return 2
    program, _module, problem = resolve_program(args.package, args.executable)
    if problem is not None:
        print(f'mindgrasp run: {problem}', file=sys.stderr)
        return 2
    sys.stdout.flush()
    os.execv(program[0], [*program, *args.argv])  # the node replaces this process, as ros2 run
    return 0  # pragma: no cover - execv does not return
