"""``--lockstep``: a launch's nodes composed in one process on simulated time.

:func:`lockstep_components` resolves a launch (profile or file, with its arguments; plus an
optional overlay launch file whose nodes replace same-named ones) into the nodes to compose, as
``mindgrasp launch`` would start them, with the lock-step substitutions of
:data:`LOCKSTEP_NODES`: LSL runs on wall time, so the virtual amplifier publishes ``/eeg/raw``
itself (``output:=ros``) and the LSL acquisition node is left out. With a ``bag`` directory the
launch's recorder is composed too (the same node, topics and arguments as in a live run; it
discovers the topics from the in-process graph and stamps messages with simulated time);
without one (the experiments, which write records) the launch runs with ``record:=false``.
:func:`run_lockstep` steps them with :class:`mindgrasp_ros.composition.LockstepRunner` until a
node is done. The experiments (:mod:`mindgrasp_experiments.engine`) build on these.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from mindgrasp_bringup.launch_system import params as ros_params
from mindgrasp_bringup.launch_system import rundir

__all__ = ['LOCKSTEP_NODES', 'RECORDER_MODULE', 'LockstepComponent', 'check_eeg_source',
           'lockstep_components', 'run_lockstep', 'set_log_level']

#: node module -> None (left out in lock-step, with the reason) or parameters set in lock-step
LOCKSTEP_NODES: dict[str, str | dict[str, Any]] = {
    'mindgrasp_eeg.acquisition_node': 'LSL runs on wall time; the virtual amplifier publishes '
                                      '/eeg/raw itself in lock-step',
    # the runner's own /clock is not a topic of the launch (a live run has none); /rosout and
    # /parameter_events are left out: they name paths of the run, and an experiment's bag is
    # the same bit for bit when run again (nothing changes parameters live in lock-step)
    'mindgrasp_bringup.bag.recorder_node': {'exclude_regex': '^/clock$',
                                            'include_ros_topics': False, 'parameter_changes': ''},
    'mindgrasp_eeg.virtual_amp_node': {'output': 'ros'},
}

#: the recorder's node module (its ``output`` is the bag directory)
RECORDER_MODULE = 'mindgrasp_bringup.bag.recorder_node'
#: the LSL acquisition node, and the node that replaces it in lock-step
_ACQUISITION, _VIRTUAL_AMP = 'mindgrasp_eeg.acquisition_node', 'mindgrasp_eeg.virtual_amp_node'


@dataclass
class LockstepComponent:
    """A node of the composed graph: its label, module and ROS arguments."""

    label: str
    module: str
    ros_args: list[str]
    parameters: dict[str, Any] = field(default_factory=dict)


def lockstep_components(launch: str | Path, arguments: Sequence[str] | Mapping[str, Any],
                        params_dir: Path, *, overlay: str | Path | None = None,
                        log: Any = None, bag: Path | None = None) -> list[LockstepComponent]:
    """The nodes of ``launch`` (a profile or a launch file) to compose in lock-step.

    ``overlay``: a user's launch file whose nodes replace the profile's nodes of the same name
    (another classifier, another controller) or are added. ``bag``: the directory the launch's
    recorder writes (as ``<run dir>/bag`` of a live run; the launch's ``record:=false`` still
    leaves it out); None runs without the recorder. Parameter files of every node are written to
    ``params_dir``. Raises :class:`LaunchError` naming the problem and the fix.
    """
    from mindgrasp_bringup.launch_system import LaunchError, LaunchService

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
    check_eeg_source(processes)
    out = []
    for spec in processes:
        if not spec.is_node:
            msg = (f"'{spec.label}' is not a node ({spec.program[:1]}); lock-step composes "
                   'Python node modules only: leave it out of the launch file.')
            raise LaunchError(msg)
        if spec.module is None:
            msg = (f"'{spec.label}' is not a Python node module, so it cannot be composed in "
                   'lock-step; give it as Node(package=..., executable=...) of a Python '
                   'package.')
            raise LaunchError(msg)
        rule = LOCKSTEP_NODES.get(spec.module)
        if isinstance(rule, str):
            if log is not None:
                log(f"lock-step: '{spec.label}' left out ({rule}).")
            continue
        params = dict(spec.parameters)
        if isinstance(rule, dict):
            params.update(rule)
        if spec.module == RECORDER_MODULE and bag is not None:
            params['output'] = str(bag)
        path = params_dir / f'{spec.label}.yaml'
        rundir.write_yaml(path, ros_params.dump_parameters({'/**': params}),
                          header=f'parameters of {spec.label} (lock-step)')
        if spec.arguments:
            msg = (f"'{spec.label}' has command-line arguments {spec.arguments}; composed nodes "
                   'take ROS arguments only: give them as parameters.')
            raise LaunchError(msg)
        cmd = spec.command(path)
        ros_args = cmd[cmd.index('--ros-args') + 1:]
        out.append(LockstepComponent(spec.label, spec.module, ros_args, params))
    # The recorder is composed last: its first discovery, when it is constructed, sees every
    # node's topics, so the bag starts at the first step (a live recorder, started first, finds
    # the other processes as they come up, seconds before they publish).
    out.sort(key=lambda c: c.module == RECORDER_MODULE)
    return out


def check_eeg_source(processes: Sequence[Any]) -> None:
    """Raise :class:`LaunchError` when the launch's EEG comes from an LSL amplifier: lock-step
    leaves the acquisition node out, and only the virtual amplifier can replace it."""
    from mindgrasp_bringup.launch_system import LaunchError

    modules = {spec.module for spec in processes}
    if _ACQUISITION in modules and _VIRTUAL_AMP not in modules:
        msg = ('lock-step cannot take EEG from an LSL stream: LSL runs on wall time, so the '
               'acquisition node is left out, and this launch has no virtual amplifier to '
               'publish /eeg/raw on simulated time. Start one (amp:=virtual; virtual_amp:=true '
               'in the eeg profile), or launch without --lockstep.')
        raise LaunchError(msg)


def set_log_level(level: str) -> None:
    """Every node logger of this process at ``level`` (as ``--ros-args --log-level``)."""
    from mindgrasp_ros import using_real_rclpy

    if using_real_rclpy():  # pragma: no cover - needs a ROS 2 installation
        from rclpy.logging import LoggingSeverity, set_logger_level

        set_logger_level('', getattr(LoggingSeverity, level.upper()))
        return
    from mindgrasp_ros.runtime.logging import set_logger_level

    set_logger_level('', level)


def _exit_code_text(node: Any) -> str | None:
    """'ended with exit code N' for a node that ended with a non-zero code (``done`` holds the
    code its process would exit with, e.g. a prompter that gave up), else None."""
    from mindgrasp_ros.node_main import is_done

    done = getattr(node, 'done', None)
    if not is_done(node) or isinstance(done, bool) or done.exception() is not None:
        return None
    code = done.result()
    if isinstance(code, int) and not isinstance(code, bool) and code != 0:
        return f'ended with exit code {code}'
    return None


def run_lockstep(components: Sequence[LockstepComponent], *, step_s: float = 0.02,
                 duration_s: float = 0.0, log: Any = print) -> int:
    """``mindgrasp launch <profile> --lockstep``: compose every node, step until a node is done
    (``done``), ``duration_s`` simulated seconds (> 0) or Ctrl-C. Returns 1 when a node raised
    or reports an ``error``, else 0."""
    from mindgrasp_ros.composition import LockstepRunner, NodeCallbackError, load_node_class
    from mindgrasp_ros.node_main import error_text, is_done

    runner = LockstepRunner(start_time_s=0.0)   # nodes start with the clock at 0: no jump
    wall0, cpu0 = time.perf_counter(), time.process_time()
    code = 0
    try:
        nodes = [runner.add(load_node_class(c.module), ros_args=c.ros_args) for c in components]
        end = runner.time_s + duration_s if duration_s > 0 else math.inf
        while runner.time_s < end and not any(is_done(n) for n in nodes):
            runner.step(step_s)
        errors = [(n.get_name(), error_text(n) or _exit_code_text(n)) for n in nodes
                  if error_text(n) or _exit_code_text(n)]
        for name, error in errors:
            log(f'[{name}] ERROR: {error}')
        code = 1 if errors else 0
    except NodeCallbackError as exc:
        log(f'[{exc.node}] ERROR: {type(exc.error).__name__}: {exc.error}')
        code = 1
    except KeyboardInterrupt:
        pass
    finally:
        wall = time.perf_counter() - wall0
        sim = runner.time_s
        cpu = time.process_time() - cpu0
        log(f'lock-step: simulated {sim:.1f} s in {wall:.1f} s wall time (real-time factor '
            f'{sim / max(wall, 1e-9):.1f}, {cpu / max(sim, 1e-9):.3f} CPU s per simulated s).')
        runner.close()
    return code
