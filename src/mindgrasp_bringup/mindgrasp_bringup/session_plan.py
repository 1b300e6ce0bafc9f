"""Calibration session plans: the YAML schema of a plan and its phases, the built-in plans, and
which nodes of a phase's launch prompt its trials (ROS-free; :mod:`mindgrasp_bringup.session`
runs them).

A plan is a YAML file (``plans/graded.yaml`` is the paper's graded protocol)::

    name: graded
    training: {min_trials: 5, cv: 5}      # mindgrasp train classifier settings
    phases:
      - {name: graz, kind: graz, trials: 40}
      - {name: test, kind: test, trials: 20}

Phase keys: ``name``, ``kind`` (graz | trainer | test), ``trials``, ``feedback`` (graz), ``train``
(retrain after the phase; default true for graz and trainer), ``duration`` (s, 0 none), ``args``
(more launch arguments), ``params`` (ROS parameters per node name).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields
from functools import lru_cache
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.resources import resource_path
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.topics import DISPLAY_FLIP, TRAINER_PROMPT
from mindgrasp_trainer.protocol import TrainerError

__all__ = ['KINDS', 'LABEL_TOPICS', 'PLAN_DIR', 'Phase', 'Plan', 'SessionError',
           'calibration_plan', 'check_subject', 'load_plan', 'named_nodes', 'phase_nodes',
           'prompters']

PLAN_DIR = resource_path('mindgrasp_bringup', 'plans')
KINDS = {'graz': 'graz', 'trainer': 'trainer', 'test': 'demo'}   # phase kind -> launch profile
PHASE_KEYS = {'name', 'kind', 'trials', 'feedback', 'train', 'duration', 'args', 'params'}
PLAN_KEYS = {'name', 'description', 'training', 'phases'}
TRAINING_KEYS = {'min_trials', 'cv', 'pipeline', 'tmin', 'tmax', 'seed', 'labels'}
#: where training labels come from: the prompters' stamps, or when the display drew them
LABEL_TOPICS = {'prompt': TRAINER_PROMPT.name, 'display': DISPLAY_FLIP.name}


class SessionError(TrainerError):
    """A bad plan, subject ID or session state; the message names the problem and the fix."""


def check_subject(subject: str) -> str:
    """A subject ID is a folder name: letters, digits, ``-`` and ``_`` only."""
    if not re.fullmatch(r'[A-Za-z0-9][A-Za-z0-9_-]{0,63}', subject or ''):
        msg = (f'The subject ID {subject!r} is not usable as a folder name; use letters, digits, '
               "'-' and '_' only (no '/', '..' or spaces), e.g. S01.")
        raise SessionError(msg)
    return subject


@dataclass
class Phase:
    """One phase of a plan (see the module docstring for the keys)."""

    name: str
    kind: str
    trials: int
    feedback: bool = False
    train: bool = True
    duration: float = 0.0
    args: dict[str, str] = field(default_factory=dict)
    params: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def profile(self) -> str:
        return KINDS[self.kind]


@dataclass
class Plan:
    name: str
    phases: list[Phase]
    training: dict[str, Any]
    source: dict[str, Any]


def load_plan(plan: str) -> Plan:
    """A plan by name (``plans/<name>.yaml``) or path; unknown phases or keys are errors."""
    path = Path(plan)
    if not path.suffix:
        path = PLAN_DIR / f'{plan}.yaml'
    if not path.is_file():
        known = ', '.join(sorted(p.stem for p in PLAN_DIR.glob('*.yaml')))
        msg = f'No plan {plan!r}: give a plan name ({known}) or the path of a plan YAML file.'
        raise SessionError(msg)
    try:
        data = yaml.safe_load(path.read_text(encoding='utf-8')) or {}
    except yaml.YAMLError as err:
        msg = f'The plan {path} is not valid YAML: {yaml_error_text(err)}'
        raise SessionError(msg) from None
    except UnicodeDecodeError:
        msg = f'The plan {path} is not a text (UTF-8) YAML file; give the path of a plan YAML file.'
        raise SessionError(msg) from None
    where = f'plan {path.name}'
    if not isinstance(data, dict) or not isinstance(data.get('phases'), list) or \
            not data['phases']:
        msg = f"The {where} needs a non-empty list 'phases'; see {PLAN_DIR / 'graded.yaml'}."
        raise SessionError(msg)
    _unknown(set(data) - PLAN_KEYS, where, PLAN_KEYS)
    training = dict(data.get('training') or {})
    _unknown(set(training) - TRAINING_KEYS, f'{where} training', TRAINING_KEYS)
    if training.get('labels', 'prompt') not in LABEL_TOPICS:
        msg = (f"The {where} training labels {training['labels']!r} are unknown; use prompt "
               '(the prompter\'s stamps) or display (when the display drew each cue).')
        raise SessionError(msg)
    phases, names = [], set()
    for i, raw in enumerate(data['phases'], start=1):
        if not isinstance(raw, dict):
            msg = f'Phase {i} of the {where} is not a mapping of keys; write e.g. ' \
                  '{name: graz, kind: graz, trials: 40}.'
            raise SessionError(msg)
        _unknown(set(raw) - PHASE_KEYS, f'{where} phase {i}', PHASE_KEYS)
        kind = raw.get('kind')
        if kind not in KINDS:
            msg = (f'Phase {i} of the {where} has the unknown kind {kind!r}; use one of '
                   f"{', '.join(KINDS)}.")
            raise SessionError(msg)
        name = str(raw.get('name') or kind)
        check_name = re.fullmatch(r'[A-Za-z0-9_-]+', name)
        if not check_name or name in names:
            msg = f'Phase {i} of the {where}: the name {name!r} is not a unique folder name.'
            raise SessionError(msg)
        names.add(name)
        trials = raw.get('trials', 40)
        if not isinstance(trials, int) or trials < 1:
            msg = f'Phase {name} of the {where}: trials must be a positive integer, not {trials!r}.'
            raise SessionError(msg)
        phases.append(Phase(
            name=name, kind=kind, trials=trials, feedback=bool(raw.get('feedback', False)),
            train=bool(raw.get('train', kind != 'test')),
            duration=float(raw.get('duration', 0.0)), args={
                str(k): str(v) for k, v in (raw.get('args') or {}).items()},
            params=dict(raw.get('params') or {})))
    return Plan(str(data.get('name') or path.stem), phases, training, data)


@lru_cache(maxsize=16)
def _resolved_nodes(profile: str, arguments: tuple[tuple[str, str], ...]
                    ) -> tuple[tuple[str, NodeTraits], ...]:
    from mindgrasp_launch import LaunchError, LaunchService
    from mindgrasp_launch.lockstep import node_traits

    try:
        plan = LaunchService(profile, dict(arguments)).plan(strict=False)
        return tuple((spec.node_name or spec.label, node_traits(spec))
                     for spec in plan.processes if spec.is_node)
    except LaunchError as exc:
        msg = f'The launch {profile!r} cannot start: {exc}'
        raise SessionError(msg) from None


def phase_nodes(profile: str, arguments: Mapping[str, str] | None = None
                ) -> dict[str, NodeTraits]:
    """Node name -> :class:`NodeTraits` of every node ``mindgrasp launch <profile>`` starts with
    ``arguments`` (resolved as the launcher resolves them; nothing starts). Cached: a session
    asks once per phase."""
    return dict(_resolved_nodes(profile, tuple(sorted((arguments or {}).items()))))


def named_nodes(nodes: Mapping[str, NodeTraits], test: Callable[[NodeTraits], bool],
           parameter: str = '') -> list[str]:
    """Names of the nodes whose traits pass ``test`` and, with ``parameter``, whose parameter
    dataclass declares it (a parameter file's value for an undeclared name is an error)."""
    return [name for name, traits in nodes.items() if test(traits) and (
        not parameter or (traits.parameters is not None
                          and parameter in {f.name for f in fields(traits.parameters)}))]


def prompters(nodes: Mapping[str, NodeTraits], kind: str, parameter: str = '') -> list[str]:
    """The nodes that prompt a phase of ``kind`` (whose end ends its launch)."""
    return named_nodes(nodes, lambda traits: kind in traits.prompts, parameter)


def _phase_classes(phase: Phase) -> int:
    """Number of classes a phase prompts (its prompter's ``classes`` parameter, else 4)."""
    for node in prompters(phase_nodes(phase.profile), phase.kind):
        classes = phase.params.get(node, {}).get('classes')
        if isinstance(classes, list) and classes:
            return len(classes)
    return 4


def calibration_plan(plan: Plan, trials_per_class: int, virtual_accuracy: float,
                     seed: int = 0) -> Plan:
    """The plan for ``mindgrasp session calibrate``: its Graz and Trainer phases with
    ``trials_per_class`` trials of each class, the virtual subject right with probability
    ``virtual_accuracy``, and a last Graz phase of the same size (``heldout``, not trained on)
    that scores the final model."""
    if not isinstance(trials_per_class, int) or trials_per_class < 2:
        msg = (f'--trials-per-class must be an integer of at least 2, not {trials_per_class!r}; '
               'training needs a few trials of each class (5 or more is sensible).')
        raise SessionError(msg)
    if not 0.0 <= virtual_accuracy <= 1.0:
        msg = (f'--virtual-accuracy must be a probability from 0 to 1, not {virtual_accuracy!r}; '
               'e.g. 0.9 (the virtual subject imagines the prompted class 90 % of the time).')
        raise SessionError(msg)
    phases = []
    for phase in plan.phases:
        if phase.kind == 'test':
            continue
        params = {name: dict(values) for name, values in phase.params.items()}
        for name in named_nodes(phase_nodes(phase.profile), lambda t: t.virtual_subject):
            params.setdefault(name, {})['accuracy'] = float(virtual_accuracy)
        phases.append(Phase(phase.name, phase.kind, trials_per_class * _phase_classes(phase),
                            phase.feedback, phase.train, phase.duration, dict(phase.args),
                            params))
    if not phases:
        msg = f'The plan {plan.name} has no Graz or Trainer phase to calibrate on.'
        raise SessionError(msg)
    graz = next((p for p in phases if p.kind == 'graz'), None)
    nodes = phase_nodes(KINDS['graz'])
    subjects = named_nodes(nodes, lambda t: t.virtual_subject)
    kept = {*subjects, *prompters(nodes, 'graz')}
    params = {name: dict(v) for name, v in (graz.params if graz else {}).items() if name in kept}
    for name in subjects:
        params.setdefault(name, {})['accuracy'] = float(virtual_accuracy)
    n_classes = _phase_classes(graz) if graz else 4
    heldout = Phase('heldout', 'graz', trials_per_class * n_classes, train=False,
                    args={'seed': str(seed + 1000)}, params=params)
    source = {**plan.source, 'name': f'{plan.name} (calibrate)',
              'phases': [_phase_source(p) for p in (*phases, heldout)]}
    return Plan(f'{plan.name} (calibrate)', [*phases, heldout], plan.training, source)


def _phase_source(p: Phase) -> dict[str, Any]:
    out: dict[str, Any] = {'name': p.name, 'kind': p.kind, 'trials': p.trials}
    if p.feedback:
        out['feedback'] = True
    if p.train != (p.kind != 'test'):
        out['train'] = p.train
    if p.duration:
        out['duration'] = p.duration
    if p.args:
        out['args'] = p.args
    if p.params:
        out['params'] = p.params
    return out


def _unknown(keys: set, where: str, allowed: set) -> None:
    if keys:
        msg = (f"The {where} has unknown key(s) {', '.join(sorted(map(str, keys)))}; allowed: "
               f"{', '.join(sorted(allowed))}.")
        raise SessionError(msg)


