"""What a graph host must know about a node, declared on the node class itself.

A node class states its traits in a ``node_traits`` class attribute; the launcher, the lock-step
runner and the experiment engine ask the class (:func:`traits_of`) instead of keeping tables of
module names, so renaming a node or adding a seeded parameter is an edit in one file::

    class SimNode(rclpy.node.Node):
        node_traits = NodeTraits(seed_parameters=('seed', 'realism_seed'))

Sessions, replay and the report tools ask the same traits which node prompts a phase, which node
is the virtual participant or which parameter names a run's task, so no module outside a node's
package names the node (``tests/docs/test_code_rules.py`` checks it).

A class without the attribute has the defaults: no seed, composed as it is, not a trial manager.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

__all__ = ['NodeTraits', 'traits_of']


@dataclass(frozen=True)
class NodeTraits:
    """Traits of a node class for the graph hosts.

    Attributes
    ----------
    seed_parameters
        Parameters set to the trial's seed in an experiment (each trial of a
        seed gets its own derived seed, so a record depends on ``(seed, trial)`` only).
    lockstep_parameters
        Parameters set when the graph runs lock-step on simulated time
        (e.g. the virtual amplifier publishing ``/eeg/raw`` itself).
    lockstep_left_out
        Why the node is left out of a lock-step graph ('' = it is composed).
    provides
        What the node gives the graph (e.g. ``'eeg'``); a node left out in lock-step
        must have a composed node that provides the same, or the launch is refused with
        ``lockstep_missing``.
    lockstep_missing
        The one-line error when nothing composed provides what this left-out
        node provides, naming the fix.
    trial_manager
        The node that runs an experiment's trials and keeps its records; the
        engine tells it which trial to run and reads its records.
    lockstep_exclude_parameter
        The node's parameter holding a regex of topics it leaves out
        (a recorder's); lock-step adds the runner's own ``/clock`` to it, a topic that a
        live run does not have ('' = none).
    lockstep_output_parameter
        The node's parameter that takes the bag directory of a
        lock-step run (a recorder's output); such a node is composed last, so that its first
        discovery sees every node's topics ('' = none).
    parameters
        The dataclass the node declares its parameters from
        (:func:`mindgrasp_ros.params.declare_params`), so that a host checks a value's range
        and choices before it starts the node (None: checked when the node starts).
    name
        The node's own name (its constructor passes it to ``Node``), for a host that
        needs it before the node exists: the section of a parameter file, a diagnostic
        status ('' = not declared).
    prompts
        Session phase kinds (``'graz'``, ``'trainer'``, ``'test'``) whose trials the
        node prompts; its end ends the phase's launch, and its run's task is that kind.
    task_parameter
        The node's parameter naming the task of its run (a trial manager's
        ``protocol``), read from the run's parameter files ('' = none).
    participant_screen
        The screen the participant looks at (a session sets its frame
        rates and the certainty that fills its feedback bar).
    virtual_subject
        The virtual participant (a session's ``--virtual-accuracy`` sets its
        ``accuracy``; a fitted head's parameters are its parameters).
    periodic
        Topics the node publishes at a rate set by one of its parameters: topic ->
        (parameter, ``'period'`` in s or ``'rate'`` in Hz), the nominal rate of the
        latency report.
    """

    seed_parameters: tuple[str, ...] = ()
    lockstep_parameters: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    lockstep_left_out: str = ''
    provides: tuple[str, ...] = ()
    lockstep_missing: str = ''
    trial_manager: bool = False
    lockstep_exclude_parameter: str = ''
    lockstep_output_parameter: str = ''
    parameters: type | None = None
    name: str = ''
    prompts: tuple[str, ...] = ()
    task_parameter: str = ''
    participant_screen: bool = False
    virtual_subject: bool = False
    periodic: Mapping[str, tuple[str, str]] = field(
        default_factory=lambda: MappingProxyType({}))


_DEFAULT = NodeTraits()


def traits_of(node_class: type) -> NodeTraits:
    """The :class:`NodeTraits` a node class declares (the defaults when it declares none)."""
    traits = getattr(node_class, 'node_traits', _DEFAULT)
    if not isinstance(traits, NodeTraits):
        msg = (f'{node_class.__module__}.{node_class.__qualname__}.node_traits must be a '
               f'NodeTraits, not {type(traits).__name__}.')
        raise TypeError(msg)
    return traits
