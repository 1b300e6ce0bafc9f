"""The motor-imagery classes: names and indices as in ``mindgrasp_msgs/MIPrediction`` and
``mindgrasp_msgs/Prompt`` (one definition for the EEG source, trainer, classifier and controller).
"""

from __future__ import annotations

from enum import IntEnum

import numpy as np

from mindgrasp_common.errors import CommonError

__all__ = ['CLASS_NAMES', 'DECODER_CLASS_NAMES', 'NO_CLASS', 'REST', 'MiClass',
           'class_index', 'class_name', 'decoder_class_index']


class MiClass(IntEnum):
    """Motor-imagery classes (``MIPrediction`` constants); what each one does in the controller
    is in :mod:`mindgrasp_fsm.grasp_fsm`."""

    LEFT_HAND = 0
    RIGHT_HAND = 1
    BOTH_HANDS = 2
    BOTH_FEET = 3


#: class names by class index
CLASS_NAMES: tuple[str, ...] = tuple(c.name.lower() for c in MiClass)
#: ``Prompt.NO_CLASS``: a prompt (or a moment) that asks for no class (fixation, rest, end)
NO_CLASS = 255
#: ``MIPrediction.REST``: the decoder class "no imagery". A decoder may learn it beside the four
#: imagery classes (rest epochs of the calibration) so that it can say "nothing meant" instead of
#: picking the least unlikely imagery class; it is not a command and no prompt asks for it.
REST = 4
#: names of the classes a decoder can know, by index (the imagery classes, then ``rest``)
DECODER_CLASS_NAMES: tuple[str, ...] = (*CLASS_NAMES, 'rest')


def class_index(name_or_index: str | int) -> int:
    """Class index from a name (``'left_hand'``, ``'Left hand'``) or an index (``2``, ``'2'``).

    Raises
    ------
    CommonError
        Unknown name or an index outside 0..3.
    """
    if isinstance(name_or_index, (int, np.integer)) and not isinstance(name_or_index, bool):
        if 0 <= int(name_or_index) < len(CLASS_NAMES):
            return int(name_or_index)
    else:
        key = str(name_or_index).strip().lower().replace(' ', '_').replace('-', '_')
        if key.isdigit() and int(key) < len(CLASS_NAMES):
            return int(key)
        if key in CLASS_NAMES:
            return CLASS_NAMES.index(key)
    msg = f'Unknown MI class {name_or_index!r}; use one of {list(CLASS_NAMES)} or 0-3.'
    raise CommonError(msg)


def class_name(index: int | None) -> str:
    """Name of a class index; ``'rest'`` for ``None``, :data:`NO_CLASS` or :data:`REST`."""
    if index is None or index in (NO_CLASS, REST):
        return 'rest'
    return CLASS_NAMES[index]


def decoder_class_index(name_or_index: str | int) -> int:
    """Index of a class a decoder can know: an imagery class (:func:`class_index`) or ``rest``
    (:data:`REST`).

    Raises
    ------
    CommonError
        Unknown name or index.
    """
    if isinstance(name_or_index, (int, np.integer)) and not isinstance(name_or_index, bool):
        if int(name_or_index) == REST:
            return REST
    elif str(name_or_index).strip().lower() in ('rest', str(REST)):
        return REST
    try:
        return class_index(name_or_index)
    except CommonError:
        msg = (f'Unknown decoder class {name_or_index!r}; use one of '
               f'{list(DECODER_CLASS_NAMES)} or 0-{REST}.')
        raise CommonError(msg) from None
