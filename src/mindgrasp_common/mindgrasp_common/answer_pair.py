"""The scan paradigm's answer pair: which imagery means "yes" and which means "no" for one person.

People differ in the imagery they can produce reliably, so the pair is chosen per person at
calibration (:mod:`mindgrasp_classifier.answer_pair`) and kept in the classifier model
(``answer_pair: {name, yes, no}``, class names). Each side is a *set* of decoder classes: the
evidence for "yes" is ``log sum p(yes classes) - log sum p(no classes)``
(:mod:`mindgrasp_fsm.evidence`). A person answers a side by imagining its first class (for
``mi_rest`` the imagery class that person separates best from rest; any imagery counts).

Named pairs (the contract with the population experiments):

==============  ======================================  =============
name            yes                                     no
==============  ======================================  =============
``hands_feet``  both hands                              both feet
``left_right``  left hand (or right hand, if so chosen)  right hand
``mi_rest``     imagery (the four classes)              rest
``<yes>_<no>``  any other pair of decoder classes, e.g. ``both_hands_rest``
==============  ======================================  =============

    >>> pair = answer_pair('left_right')
    >>> pair.yes, pair.no, pair.describe()
    ((0,), (1,), 'yes: imagine the left hand; no: imagine the right hand')
    >>> answer_pair('both_hands_rest').no
    (4,)
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import DECODER_CLASS_NAMES, REST, decoder_class_index

__all__ = ['DEFAULT_PAIR', 'NAMED_PAIRS', 'AnswerPair', 'answer_pair', 'model_decision']

#: named pairs: name -> (yes classes, no classes)
NAMED_PAIRS: dict[str, tuple[tuple[int, ...], tuple[int, ...]]] = {
    'hands_feet': ((2,), (3,)),
    'left_right': ((0,), (1,)),
    'mi_rest': ((0, 1, 2, 3), (REST,)),
}
#: the pair when nothing chose another (the scan paradigm's original answer)
DEFAULT_PAIR = 'hands_feet'

_SPOKEN = {0: 'the left hand', 1: 'the right hand', 2: 'both hands', 3: 'both feet'}


@dataclass(frozen=True)
class AnswerPair:
    """One answer pair.

    Attributes
    ----------
    name : str
        ``hands_feet``, ``left_right``, ``mi_rest`` or ``<yes>_<no>``.
    yes, no : tuple of int
        Decoder classes (0-3 imagery, 4 rest) of each answer; the first is the one a person
        imagines to give it.
    """

    name: str
    yes: tuple[int, ...]
    no: tuple[int, ...]

    def __post_init__(self) -> None:
        if not self.yes or not self.no or set(self.yes) & set(self.no):
            msg = (f'The answer pair {self.name!r} needs two disjoint, non-empty sets of classes; '
                   f'got yes {list(self.yes)} and no {list(self.no)}.')
            raise CommonError(msg)

    @property
    def yes_class(self) -> int | None:
        """The class a person imagines for "yes" (None: rest)."""
        return None if self.yes[0] == REST else self.yes[0]

    @property
    def no_class(self) -> int | None:
        """The class a person imagines for "no" (None: rest)."""
        return None if self.no[0] == REST else self.no[0]

    @property
    def classes(self) -> set[int]:
        """Every class of the pair."""
        return {*self.yes, *self.no}

    def to_dict(self) -> dict[str, Any]:
        """``{name, yes: [class names], no: [class names]}`` (the model file's form)."""
        return {'name': self.name, 'yes': [DECODER_CLASS_NAMES[c] for c in self.yes],
                'no': [DECODER_CLASS_NAMES[c] for c in self.no]}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> AnswerPair:
        """The pair of a model file's ``answer_pair`` entry (class names or indices)."""
        try:
            return cls(str(data['name']), tuple(decoder_class_index(c) for c in data['yes']),
                       tuple(decoder_class_index(c) for c in data['no']))
        except (KeyError, TypeError) as exc:
            msg = (f'The answer pair {dict(data)!r} is incomplete ({exc}); it needs name, yes '
                   'and no (class names).')
            raise CommonError(msg) from None

    def _say(self, side: tuple[int, ...]) -> str:
        if side == (REST,):
            return 'rest (imagine nothing)'
        if set(side) == {0, 1, 2, 3}:
            return (f'imagine a movement ({_SPOKEN[side[0]]} works best for you; any counts)')
        return 'imagine ' + ' or '.join(_SPOKEN.get(c, 'rest') for c in side)

    def describe(self) -> str:
        """What the person does, in one line (participant display, session report)."""
        return f'yes: {self._say(self.yes)}; no: {self._say(self.no)}'


def answer_pair(name: str, yes: Sequence[int] | None = None,
                no: Sequence[int] | None = None) -> AnswerPair:
    """The pair called ``name`` (:data:`NAMED_PAIRS` or ``<yes class>_<no class>``).

    ``yes`` / ``no`` (class indices) give the sides explicitly (a model's reversed
    ``left_right``, the imagery order of ``mi_rest``); otherwise they follow from the name.

    Raises
    ------
    CommonError
        A name that is neither a named pair nor two decoder class names joined by ``_``.
    """
    if yes is not None and no is not None:
        return AnswerPair(name, tuple(int(c) for c in yes), tuple(int(c) for c in no))
    if name in NAMED_PAIRS:
        y, n = NAMED_PAIRS[name]
        return AnswerPair(name, y, n)
    for a in DECODER_CLASS_NAMES:
        for b in DECODER_CLASS_NAMES:
            if a != b and name == f'{a}_{b}':
                return AnswerPair(name, (decoder_class_index(a),), (decoder_class_index(b),))
    msg = (f'Unknown answer pair {name!r}; use auto, {", ".join(NAMED_PAIRS)} or two class names '
           f'joined by _ (<yes>_<no>, classes {list(DECODER_CLASS_NAMES)}), e.g. both_hands_rest.')
    raise CommonError(msg)


def model_decision(path: str | Path) -> tuple[AnswerPair | None, dict[str, float] | None]:
    """The answer pair and decision thresholds (nat s: confirm, pass, affirm, cancel) a classifier
    model chose at calibration; (None, None) for a model without them. Reads the model's JSON
    only (no arrays, nothing executed).

    Raises
    ------
    CommonError
        A model file that cannot be read or holds a malformed pair.
    """
    from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

    try:
        p = resolve_path(path, 'mindgrasp_classifier', ('.json',))
    except ResourceNotFoundError as exc:
        raise CommonError(str(exc)) from None
    p = Path(p)
    if p.suffix != '.json':
        p = p.with_name(p.name + '.json')
    try:
        meta = json.loads(p.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        msg = f'Cannot read the classifier model {p} ({exc}); give the .json of a trained model.'
        raise CommonError(msg) from None
    pair = meta.get('answer_pair')
    thresholds = meta.get('decision_thresholds')
    return (AnswerPair.from_dict(pair) if isinstance(pair, Mapping) else None,
            {k: float(v) for k, v in thresholds.items()} if isinstance(thresholds, Mapping)
            else None)
