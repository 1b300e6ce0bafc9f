"""The scan paradigm's answer pair in the controller: which pair is in force, its thresholds,
and whether the classifier model may drive a real arm (ROS-free; used by
:class:`~mindgrasp_fsm.grasp_fsm.GraspFsm` and the fsm node)."""

from __future__ import annotations

from mindgrasp_common.answer_pair import DEFAULT_PAIR, AnswerPair, answer_pair, model_decision
from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import REST
from mindgrasp_fsm.errors import FsmError
from mindgrasp_fsm.params import FsmParams

__all__ = ['CLASS_WORDS', 'evidence_side', 'evidence_word', 'readiness_problem', 'resolve_answer']

#: the decoder's classes in words (events and messages)
CLASS_WORDS = {0: 'left hand', 1: 'right hand', 2: 'both hands', 3: 'both feet', REST: 'rest'}


def evidence_side(classes: tuple[int, ...]) -> int | list[int]:
    """One side of an answer pair for :class:`Evidence`: its class, or the set."""
    return int(classes[0]) if len(classes) == 1 else list(classes)


def evidence_word(classes: tuple[int, ...]) -> str:
    """'both-hands', 'rest', 'imagery' ...: what the evidence of one side of the pair is for."""
    return CLASS_WORDS[classes[0]].replace(' ', '-') if len(classes) == 1 else 'imagery'


def readiness_problem(params: FsmParams) -> str | None:
    """Why ``params.classifier_model`` may not drive the arm when ``require_ready_model`` is set
    (one sentence naming the override), or None: its calibration gate
    (:mod:`mindgrasp_classifier.gate`) called the person ready, or no readiness is required."""
    import json

    from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

    if not params.require_ready_model or params.autonomous:
        return None
    override = 'override with require_ready_model:=false (a bench test, or at your own risk)'
    if not params.classifier_model:
        return f'no classifier model to check (classifier_model is empty); {override}.'
    try:
        path = resolve_path(params.classifier_model, 'mindgrasp_classifier', ('.json',))
        if path.suffix != '.json':
            path = path.with_name(path.name + '.json')
        gate = json.loads(path.read_text()).get('gate') or {}
    except (OSError, ValueError, AttributeError, ResourceNotFoundError) as exc:
        return f'cannot read the gate of {params.classifier_model} ({exc}); {override}.'
    verdict = gate.get('verdict') if isinstance(gate, dict) else None
    if verdict == 'ready':
        return None
    if not verdict:
        return (f'the model {params.classifier_model} has no calibration gate verdict (calibrate '
                f'with mindgrasp session calibrate); {override}.')
    return (f"the model {params.classifier_model} is not ready ({verdict}: "
            f"{gate.get('reason', '')}); {override}.")


def resolve_answer(params: FsmParams) -> tuple[AnswerPair, dict[str, float] | None]:
    """The answer pair in force and the model's decision thresholds (nat s; None: none).

    ``answer_pair: auto`` takes the pair of ``classifier_model`` (the person's, chosen at
    calibration), :data:`~mindgrasp_common.answer_pair.DEFAULT_PAIR` without one; a name
    overrides it (a named side order as in the model when the model chose that pair).

    Raises
    ------
    FsmError
        An unknown pair name, or a classifier model that cannot be read.
    """
    chosen, thresholds = None, None
    try:
        if params.classifier_model:
            chosen, thresholds = model_decision(params.classifier_model)
        if params.answer_pair == 'auto':
            pair = chosen or answer_pair(DEFAULT_PAIR)
        elif chosen is not None and chosen.name == params.answer_pair:
            pair = chosen
        else:
            pair = answer_pair(params.answer_pair)
            thresholds = None       # the model's thresholds belong to its own pair
    except CommonError as exc:
        msg = f'The scan answer pair: {exc}'
        raise FsmError(msg) from None
    return pair, thresholds
