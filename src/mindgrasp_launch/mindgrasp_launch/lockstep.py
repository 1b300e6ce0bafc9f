"""``--lockstep``: a launch's nodes composed in one process on simulated time.

:func:`lockstep_components` resolves a launch (profile or file, with its arguments; plus an
optional overlay launch file whose nodes replace same-named ones) into the nodes to compose, as
``mindgrasp launch`` would start them, with the lock-step traits each node class declares
(:class:`mindgrasp_ros.node_traits.NodeTraits`): LSL runs on wall time, so the virtual amplifier
publishes ``/eeg/raw`` itself (``output:=ros``) and the LSL acquisition node is left out. With a
``bag`` directory the launch's recorder is composed too (the same node, topics and arguments as
in a live run; it discovers the topics from the in-process graph and stamps messages with
simulated time); without one (the experiments, which write records) the launch runs with
``record:=false``.
Each node is a :class:`~mindgrasp_ros.graph.spec.NodeSpec` (its resolved parameters typed, also
written to ``params_dir/<label>.yaml``). :func:`run_lockstep` runs them with the one graph host
(:class:`~mindgrasp_ros.graph.host.GraphRunner` under the ``Lockstep`` scheduler) until a node is
done. The experiments (:mod:`mindgrasp_experiments.engine`) build on these.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_launch import params as ros_params
from mindgrasp_launch import rundir
from mindgrasp_ros.graph.spec import NodeSpec
from mindgrasp_ros.node_traits import NodeTraits, traits_of

__all__ = ['check_left_out_nodes', 'launch_lockstep', 'lockstep_components', 'node_traits',
           'run_lockstep', 'set_log_level']

#: the runner's own /clock is not a topic of the launch (a live run has none): a recorder
#: leaves it out beside the launch's record_exclude_regex (NodeTraits.lockstep_exclude_parameter)
_CLOCK_EXCLUDE = '^/clock$'


def lockstep_components(launch: str | Path, arguments: Sequence[str] | Mapping[str, Any],
                        params_dir: Path, *, overlay: str | Path | None = None,
                        log: Any = None, bag: Path | None = None) -> list[NodeSpec]:
    """The nodes of ``launch`` (a profile or a launch file) to compose in lock-step.

    ``overlay``: a user's launch file whose nodes replace the profile's nodes of the same name
    (another classifier, another controller) or are added. ``bag``: the directory the launch's
    recorder writes (as ``<run dir>/bag`` of a live run; the launch's ``record:=false`` still
    leaves it out); None runs without the recorder. Parameter files of every node are written to
    ``params_dir`` (the run's record of them); each spec holds them typed, as the node reads that
    file. Raises :class:`LaunchError` naming the problem and the fix.
    """
    from mindgrasp_launch import LaunchError, LaunchService
    from mindgrasp_ros.runtime.arguments import load_params_file

    args = dict(arguments) if isinstance(arguments, Mapping) else \
        dict(a.split(':=', 1) for a in arguments)
    if bag is None:
        args['record'] = 'false'
    processes = list(LaunchService(launch, args).plan().processes)
    if overlay is not None:
        user = LaunchService(overlay)
        declared = {a.name for a in user.declared_arguments()}
        user.given = {k: v for k, v in args.items() if k in declared}
        extra = user.plan().processes
        names = {p.label for p in extra}
        processes = [p for p in processes if p.label not in names] + list(extra)
    traits_of_spec = [node_traits(spec) for spec in processes]
    check_left_out_nodes(processes, traits_of_spec)
    out, last = [], []
    for spec, traits in zip(processes, traits_of_spec, strict=True):
        if not spec.is_node:
            msg = (f"'{spec.label}' is not a node ({spec.program[:1]}); lock-step composes "
                   'Python node modules only: leave it out of the launch file.')
            raise LaunchError(msg)
        if spec.module is None:
            msg = (f"'{spec.label}' is not a Python node module, so it cannot be composed in "
                   'lock-step; give it as Node(package=..., executable=...) of a Python '
                   'package.')
            raise LaunchError(msg)
        if traits.lockstep_left_out:
            if log is not None:
                log(f"lock-step: '{spec.label}' left out ({traits.lockstep_left_out}).")
            continue
        params = {**spec.parameters, **traits.lockstep_parameters}
        if traits.lockstep_exclude_parameter:
            exclude = params.get(traits.lockstep_exclude_parameter, '')
            params[traits.lockstep_exclude_parameter] = \
                f'{_CLOCK_EXCLUDE}|{exclude}' if exclude else _CLOCK_EXCLUDE
        if traits.lockstep_output_parameter and bag is not None:
            params[traits.lockstep_output_parameter] = str(bag)
        path = params_dir / f'{spec.label}.yaml'
        rundir.write_yaml(path, ros_params.dump_parameters({'/**': params}),
                          header=f'parameters of {spec.label} (lock-step)')
        if spec.arguments:
            msg = (f"'{spec.label}' has command-line arguments {spec.arguments}; composed nodes "
                   'take ROS arguments only: give them as parameters.')
            raise LaunchError(msg)
        # typed as the node would read them from that file (tuples become lists, ...)
        component = NodeSpec(spec.label, spec.module, name=spec.node_name or '',
                             parameters=load_params_file(path, None),
                             remaps=dict(spec.remappings),
                             ros_args=[*(['-r', f'__ns:={spec.namespace}'] if spec.namespace
                                         else []), *spec.ros_arguments])
        (last if traits.lockstep_output_parameter else out).append(component)
    # The recorder is composed last: its first discovery, when it is constructed, sees every
    # node's topics, so the bag starts at the first step (a live recorder, started first, finds
    # the other processes as they come up, seconds before they publish).
    return out + last


def node_traits(spec: Any) -> NodeTraits:
    """The traits the node class of a launch process declares (defaults for other programs);
    :class:`LaunchError` when its module cannot be loaded."""
    from mindgrasp_launch import LaunchError
    from mindgrasp_ros.errors import CompositionError
    from mindgrasp_ros.graph.loader import load_node_class

    if spec.module is None:
        return traits_of(object)
    try:
        return traits_of(load_node_class(spec.module))
    except CompositionError as exc:
        msg = f"'{spec.label}' cannot be composed: {exc}"
        raise LaunchError(msg) from None


def check_left_out_nodes(processes: Sequence[Any],
                         traits: Sequence[NodeTraits] | None = None) -> None:
    """Raise :class:`LaunchError` when a node that lock-step leaves out (the LSL acquisition
    node) provides something that no composed node provides (EEG: the virtual amplifier).
    ``traits``: those of ``processes``, in order, when the caller has them already."""
    from mindgrasp_launch import LaunchError

    if traits is None:
        traits = [node_traits(spec) for spec in processes]
    composed = {what for t in traits if not t.lockstep_left_out for what in t.provides}
    for t in traits:
        if t.lockstep_left_out and not set(t.provides) <= composed:
            raise LaunchError(t.lockstep_missing or
                              f'lock-step leaves a node out ({t.lockstep_left_out}) and nothing '
                              'in this launch replaces it; launch without --lockstep.')


def set_log_level(level: str) -> None:
    """Every node logger of this process at ``level`` (as ``--ros-args --log-level``)."""
    from mindgrasp_ros import using_real_rclpy

    if using_real_rclpy():  # pragma: no cover - needs a ROS 2 installation
        from rclpy.logging import LoggingSeverity, set_logger_level

        set_logger_level('', getattr(LoggingSeverity, level.upper()))
        return
    from mindgrasp_ros.runtime.logging import set_logger_level

    set_logger_level('', level)


def run_lockstep(components: Sequence[NodeSpec], *, step_s: float = 0.02,
                 duration_s: float = 0.0, log: Any = print, runner: Any = None) -> int:
    """``mindgrasp launch <profile> --lockstep``: the graph host under the lock-step scheduler,
    until a node is done (``done``), ``duration_s`` simulated seconds (> 0) or Ctrl-C; then one
    line with the real-time factor. Returns the graph's exit code
    (:meth:`~mindgrasp_ros.graph.host.GraphRunner.run`). ``runner``: a
    :class:`~mindgrasp_ros.graph.host.GraphRunner` under a ``Lockstep`` scheduler that the
    caller keeps, to see afterwards whether Ctrl-C ended the graph (``interrupted``)."""
    from mindgrasp_ros.graph.host import GraphRunner, Lockstep

    # nodes start with the clock at 0: no jump
    runner = runner if runner is not None else GraphRunner(Lockstep(step_s), log=log)
    scheduler = runner.scheduler
    wall0, cpu0 = time.perf_counter(), time.process_time()
    try:
        return runner.run(components, duration_s=duration_s)
    finally:
        wall, sim = time.perf_counter() - wall0, scheduler.time_s
        cpu = time.process_time() - cpu0
        if sim > 0:
            log(f'lock-step: simulated {sim:.1f} s in {wall:.1f} s wall time (real-time factor '
                f'{sim / max(wall, 1e-9):.1f}, {cpu / sim:.3f} CPU s per simulated s).')
        else:   # stopped (Ctrl-C) while composing: no rate to report (it read 8e8 CPU s per s)
            log(f'lock-step: stopped after {wall:.1f} s wall time, before the first simulated '
                'step.')


def launch_lockstep(service: Any, *, log: Any = print) -> int:
    """Run the launch of ``service`` (a :class:`LaunchService`, with its arguments and run
    directory option) with ``--lockstep``: every node composed on simulated time in this
    process, its recorder writing ``<run dir>/bag``; ``duration:=S`` counts simulated seconds.

    Returns the graph's exit code (1 when a node failed). Problems with the launch raise
    :class:`LaunchError` before anything is created; Ctrl-C ends the graph and sets
    ``service.stop_reason`` as a live launch does.
    """
    from mindgrasp_launch.run_report import write_run_report
    from mindgrasp_ros.graph.host import GraphRunner, Lockstep

    # argument problems are reported before anything is created
    check_left_out_nodes(service.plan().processes)
    run_dir = rundir.create_run_dir(service.name, service.run_dir_option, service.runs_root)
    service.run_dir = run_dir
    given = dict(service.given)
    duration = float(given.pop('duration', 0) or 0)
    components = lockstep_components(service.launch_file, given, run_dir / 'params', log=log,
                                     bag=run_dir / 'bag')
    log(f'lock-step: composing {len(components)} node(s) on simulated time: '
        + ', '.join(c.label for c in components) + f'; run directory {run_dir}')
    # the run's nodes as a live run lists them: the report tools ask their classes what they are
    rundir.write_yaml(run_dir / 'launch.yaml', {
        'profile': service.name, 'lockstep': True,
        'launch_file': None if service.launch_file is None else str(service.launch_file),
        'processes': [{'label': c.label, 'node': f'/{c.name or c.label}', 'module': c.module}
                      for c in components]})
    runner = GraphRunner(Lockstep(), log=log)
    previous = os.environ.get('MINDGRASP_RUN_DIR')
    os.environ['MINDGRASP_RUN_DIR'] = str(run_dir)   # the nodes' run directory (trial records)
    try:
        code = run_lockstep(components, duration_s=duration, log=log, runner=runner)
    finally:
        if previous is None:
            os.environ.pop('MINDGRASP_RUN_DIR', None)
        else:
            os.environ['MINDGRASP_RUN_DIR'] = previous
    if runner.interrupted:
        service.stop_reason = 'SIGINT received'
    # every run directory has a report; simulated time has no latencies, and it says so
    write_run_report(run_dir, service.name)
    return code
