"""The virtual subject on a fitted head, calibrated like a user before its trials.

``--subject virtual:FILE.yaml`` names the parameter file that ``mindgrasp eeg fit-virtual
--output FILE.yaml`` writes (``virtual_amp: ros__parameters:`` with ``head_seed``,
``separability``, ``lateral_separability``, ``rest_separability``, ``nonstationarity``). Before
the first trial the subject is calibrated on that head as a user is: ``mindgrasp session
calibrate``'s plan (a lock-step Graz-BCI phase through the real nodes, recorded, the classifier
trained on the bag, then a held-out Graz run of the same size that scores it;
:mod:`mindgrasp_bringup.session`). The experiment then runs on the same head with that decoder.

An optional ``calibration:`` mapping in the file changes how (defaults :data:`CALIBRATION`)::

    calibration: {trials_per_class: 20, seed: 0, accuracy: 1.0, pipeline: mdm}

The model is cached by content: the digest of the head, the calibration settings, the plan
file and :data:`FITTED_TAG` names it (``<cache>/<name>_classifier_<digest12>.json``), so a rerun
with the same head and settings reuses it; the session it came from stays beside it
(``<cache>/sessions/fitted/<name>-<digest12>/``). The cache is ``$MINDGRASP_CACHE`` if set,
else ``$XDG_CACHE_HOME/mindgrasp/fitted_subjects``, else ``~/.cache/mindgrasp/fitted_subjects``.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError

__all__ = ['CALIBRATION', 'FITTED_PREFIX', 'FITTED_TAG', 'FittedSubject', 'fitted_model',
           'head_params', 'is_fitted', 'load_fitted', 'virtual_subject_node']

FITTED_PREFIX = 'virtual:'
#: the settings ``mindgrasp eeg fit-virtual`` writes (the head model and its decodability)
HEAD_KEYS = ('head_seed', 'separability', 'lateral_separability', 'rest_separability',
             'nonstationarity')
#: how the fitted subject is calibrated unless its file says otherwise: ``trials_per_class``
#: Graz trials of each of the four classes (and as many in the held-out run), the launches'
#: ``seed``, the probability ``accuracy`` that the subject imagines the prompted class, and the
#: decoder ``pipeline`` (mdm: as the default classifier was trained)
CALIBRATION: dict[str, Any] = {'trials_per_class': 20, 'seed': 0, 'accuracy': 1.0,
                               'pipeline': 'mdm'}
#: the session plan the calibration runs (mindgrasp_bringup/plans/calibrate.yaml)
PLAN = 'calibrate'
#: part of the digest: a change to how the calibration is made recalibrates every cached subject
FITTED_TAG = 'graz_calibrate_v2'   # v2: temperature refit on the held-out run


def is_fitted(subject: str) -> bool:
    """A fitted virtual subject (``virtual:FILE.yaml``)?"""
    return subject.startswith(FITTED_PREFIX)


def head_params(subject: str) -> dict[str, Any]:
    """The experiment parameters a subject brings (a fitted subject: its head), else {}."""
    return load_fitted(subject).node_params() if is_fitted(subject) else {}


@dataclass(frozen=True)
class FittedSubject:
    """A fitted head and how to calibrate on it.

    Attributes
    ----------
    path : Path
        The subject's parameter file.
    head : dict[str, float]
        The virtual amplifier's head settings (:data:`HEAD_KEYS`; ``head_seed`` an int).
    calibration : dict[str, Any]
        :data:`CALIBRATION` with the file's ``calibration:`` values.
    """

    path: Path
    head: dict[str, Any]
    calibration: dict[str, Any]

    @property
    def name(self) -> str:
        """The file's stem, as a folder name."""
        return ''.join(c if c.isalnum() or c in '-_' else '_' for c in self.path.stem)

    def digest(self) -> str:
        """SHA-256 (hex) of what the calibrated model depends on: the head, the calibration
        settings, the plan file and :data:`FITTED_TAG`."""
        from mindgrasp_bringup.session_plan import PLAN_DIR

        plan = (PLAN_DIR / f'{PLAN}.yaml').read_text(encoding='utf-8')
        text = json.dumps({'head': self.head, 'calibration': self.calibration, 'plan': plan,
                           'tag': FITTED_TAG}, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()

    def node_params(self) -> dict[str, Any]:
        """The head as experiment parameters (``{'virtual_amp.separability': 1.129, ...}``)."""
        return {f'virtual_amp.{key}': value for key, value in self.head.items()}


def _fail(path: Path | str, problem: str) -> ExperimentError:
    return ExperimentError(
        f'The fitted virtual subject {path} {problem}; write it with mindgrasp eeg fit-virtual '
        f'--subject eegmmidb:1 --output {path} (see src/mindgrasp_eeg/README.md).')


def load_fitted(subject: str) -> FittedSubject:
    """Read ``virtual:FILE.yaml``; every problem is one :class:`ExperimentError` naming the
    file and the fix (the ``mindgrasp eeg fit-virtual`` command that writes it)."""
    import yaml

    from mindgrasp_common.cli_checks import yaml_error_text
    from mindgrasp_eeg.params import VirtualAmpParams
    from mindgrasp_ros.params import ParameterError, check_value

    path = Path(subject[len(FITTED_PREFIX):])
    if not path.is_file():
        raise _fail(path, 'does not exist')
    try:
        doc = yaml.safe_load(path.read_text(encoding='utf-8'))
    except yaml.YAMLError as exc:
        raise _fail(path, f'is not valid YAML ({yaml_error_text(exc)})') from None
    except (OSError, UnicodeDecodeError) as exc:
        raise _fail(path, f'cannot be read ({exc})') from None
    node = virtual_subject_node()
    params = (doc.get(node) or {}).get('ros__parameters') \
        if isinstance(doc, dict) and isinstance(doc.get(node), dict) else None
    if not isinstance(params, dict):
        raise _fail(path, f'has no {node}: ros__parameters: mapping (a fit written by '
                          'fit-virtual --output)')
    missing = [key for key in HEAD_KEYS if key not in params]
    if missing:
        raise _fail(path, f"lacks the fitted setting(s) {', '.join(missing)}")
    head: dict[str, Any] = {}
    for key in HEAD_KEYS:
        value = params[key]
        kind = int if key == 'head_seed' else float
        if isinstance(value, bool) or not isinstance(value, (int, float)) or \
                (kind is int and not isinstance(value, int)):
            wanted = 'an integer' if kind is int else 'a number'
            raise _fail(path, f'has {key}: {value!r}, not {wanted}')
        try:
            check_value(VirtualAmpParams, key, value)
        except ParameterError as exc:
            raise _fail(path, f'is out of range: {str(exc).rstrip(".")}') from None
        head[key] = kind(value)
    extra = set(doc) - {node, 'calibration'}
    if extra:
        raise _fail(path, f"has unknown top-level key(s) {', '.join(sorted(map(str, extra)))} "
                          f'(allowed: {node}, calibration)')
    return FittedSubject(path, head, _calibration(path, doc.get('calibration') or {}))


def _calibration(path: Path, given: Any) -> dict[str, Any]:
    """:data:`CALIBRATION` updated from the file's ``calibration:`` mapping, checked."""
    if not isinstance(given, dict) or set(given) - set(CALIBRATION):
        raise _fail(path, f'has a calibration: {given!r} that is not a mapping of '
                          f"{', '.join(CALIBRATION)}")
    out = {**CALIBRATION, **given}
    tpc, seed, acc = out['trials_per_class'], out['seed'], out['accuracy']
    if not isinstance(tpc, int) or isinstance(tpc, bool) or tpc < 2:
        raise _fail(path, f'has calibration trials_per_class {tpc!r}; give an integer >= 2')
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise _fail(path, f'has calibration seed {seed!r}; give an integer >= 0')
    if not isinstance(acc, (int, float)) or isinstance(acc, bool) or not 0.0 <= acc <= 1.0:
        raise _fail(path, f'has calibration accuracy {acc!r}; give a probability 0..1')
    if out['pipeline'] not in ('mdm', 'ts_lr'):
        raise _fail(path, f"has calibration pipeline {out['pipeline']!r}; use mdm or ts_lr")
    out['accuracy'] = float(acc)
    return out


def virtual_subject_node() -> str:
    """The virtual participant's node name, the section of its parameter file (asked of the
    node class, :class:`~mindgrasp_ros.node_traits.NodeTraits`)."""
    from mindgrasp_eeg.virtual_amp_node import VirtualAmpNode
    from mindgrasp_ros.node_traits import traits_of

    return traits_of(VirtualAmpNode).name


def cache_root() -> Path:
    """Where calibrated fitted subjects are kept (see the module docstring)."""
    if os.environ.get('MINDGRASP_CACHE'):
        return Path(os.environ['MINDGRASP_CACHE']) / 'fitted_subjects'
    base = os.environ.get('XDG_CACHE_HOME') or str(Path.home() / '.cache')
    return Path(base) / 'mindgrasp' / 'fitted_subjects'


def fitted_model(subject: FittedSubject, cache: Path | None = None,
                 log: Callable[[str], None] | None = None) -> Path:
    """The decoder calibrated on ``subject``'s head (.json path), calibrating it first unless
    ``cache`` (default :func:`cache_root`) holds it already.

    The calibration is ``mindgrasp session calibrate``'s: :class:`~mindgrasp_bringup.session.
    Session` runs the plan's lock-step Graz phase and a held-out run (``mindgrasp launch graz
    --lockstep``, in this process) with the head's parameters, trains on the first
    and scores on the second. The model's provenance gets the head, the settings, the digest
    and the held-out accuracy; it is written to ``cache`` under the digest.
    """
    from mindgrasp_bringup.session import Session
    from mindgrasp_bringup.session_plan import SessionError, calibration_plan, load_plan
    from mindgrasp_classifier.errors import ClassifierError
    from mindgrasp_classifier.model import MiModel

    say = log or (lambda line: print(line, file=sys.stderr))
    cache = Path(cache) if cache is not None else cache_root()
    digest = subject.digest()
    target = cache / f'{subject.name}_classifier_{digest[:12]}.json'
    if target.is_file():
        return target
    cal = subject.calibration
    plan = calibration_plan(load_plan(PLAN), cal['trials_per_class'], cal['accuracy'],
                            cal['seed'])
    plan.training['pipeline'] = cal['pipeline']
    for phase in plan.phases:            # every phase, the held-out run too, on the fitted head
        phase.params.setdefault(virtual_subject_node(), {}).update(subject.head)
    session = Session(cache / 'sessions', 'fitted', f'{subject.name}-{digest[:12]}',
                      {'display': 'off', 'seed': str(cal['seed']),
                       'eeg_stream': f'MIndGrasp-fitted-{os.getpid()}'})
    if session.dir.exists():             # an attempt that did not finish: start afresh
        shutil.rmtree(session.dir)
    say(f'Calibrating the fitted virtual subject {subject.path} (once; {cal["trials_per_class"]} '
        f'Graz trials per class, lock-step) in {session.dir} ...')
    try:
        log_doc = session.start(plan)
        if session.run(plan, log_doc, out=say) != 0:
            msg = (f'The calibration of the fitted virtual subject {subject.path} failed; see '
                   f'{session.dir}/session.yaml and the phase logs, then run the command again.')
            raise ExperimentError(msg)
        held = session.heldout_accuracy(session.read_log())
        model = MiModel.load(session.dir / held['model_path'])
    except (SessionError, ClassifierError) as exc:
        raise ExperimentError(f'Cannot calibrate the fitted virtual subject {subject.path}: '
                              f'{exc}') from None
    model.provenance.update(
        generator=f'mindgrasp_experiments.fitted_subject.fitted_model({subject.path})',
        virtual_head=dict(subject.head), fitted_calibration=dict(cal),
        fitted_digest=digest, calibration_session=str(session.dir),
        heldout={'accuracy': held['heldout_accuracy'], 'trials': held['heldout_trials'],
                 'temperature': held['temperature']})
    target.parent.mkdir(parents=True, exist_ok=True)
    return Path(model.save(target.with_suffix('')))
