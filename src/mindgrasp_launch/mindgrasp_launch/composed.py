"""``--composed``: the node modules of a launch run in one process under one executor
(:mod:`mindgrasp_ros.graph`), with in-process delivery between them.

A node is composed when it is a Python node module (``Node(package, executable)`` that resolves
to ``python -m package.executable``) without command-line ``arguments`` (components get only
``--ros-args``). The recorder, external drivers and ``ExecuteProcess`` actions keep their own
processes. The container takes the composed nodes' place in the start order; its output is
prefixed with each node's name (from the ROS log line) and also split into ``<node>.log``.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

from mindgrasp_launch import rundir
from mindgrasp_launch.actions.execute_process import ProcessSpec
from mindgrasp_launch.actions.node import find_module
from mindgrasp_launch.errors import LaunchError

logger = logging.getLogger('launch')

CONTAINER_MODULE = 'mindgrasp_launch.container'
CONTAINER_LABEL = 'composed'


def composable(spec: ProcessSpec) -> bool:
    """Whether a process can be loaded as a component."""
    return spec.composable and not spec.daemon and not spec.arguments


def compose(processes: list[ProcessSpec], commands: list[list[str]], run_dir: Path,
            ) -> tuple[list[ProcessSpec], list[list[str]]]:
    """Replace the composable nodes by one container process; returns processes and commands.

    Writes ``<run dir>/composed.yaml`` (the components and their ROS arguments).
    """
    if not find_module('mindgrasp_ros.graph'):
        msg = ('--composed needs mindgrasp_ros.graph, which is not installed: run without '
               '--composed (one process per node).')
        raise LaunchError(msg)
    components = []
    out: list[tuple[ProcessSpec, list[str]]] = []
    container_at = None
    for spec, cmd in zip(processes, commands, strict=True):
        if not composable(spec):
            if spec.is_node and not spec.daemon:
                why = ('it is not a Python node module' if spec.module is None
                       else 'components take no command-line arguments')
                logger.info("'%s' runs in its own process: %s.", spec.label, why)
            out.append((spec, cmd))
            continue
        ros_args = cmd[cmd.index('--ros-args') + 1:] if '--ros-args' in cmd else []
        components.append({'label': spec.label, 'module': spec.module,
                           'node': spec.fully_qualified_name, 'ros_args': ros_args})
        if container_at is None:
            container_at = len(out)
    if not components:
        msg = ('--composed: no node of this launch can be composed (none is a Python node '
               'module without arguments); run without --composed.')
        raise LaunchError(msg)
    plan_file = run_dir / 'composed.yaml'
    rundir.write_yaml(plan_file, {'components': components},
                      header='nodes composed into one process (mindgrasp launch --composed)')
    container = ProcessSpec(label=CONTAINER_LABEL,
                            program=[sys.executable, '-m', CONTAINER_MODULE, str(plan_file)],
                            logger_labels={c['node'].strip('/').replace('/', '.'): c['label']
                                           for c in components if c['node']})
    out.insert(container_at or 0, (container, container.command()))
    logger.info('composing %d node(s) in one process: %s.', len(components),
                ', '.join(c['label'] for c in components))
    return [s for s, _ in out], [c for _, c in out]
