"""The scan paradigm's answer pair (mindgrasp_common.answer_pair): names, sides, what the person
is told, and the model file's entries."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mindgrasp_common.answer_pair import AnswerPair, answer_pair, model_decision
from mindgrasp_common.errors import CommonError


@pytest.mark.parametrize(('name', 'yes', 'no'), [
    ('hands_feet', (2,), (3,)), ('left_right', (0,), (1,)), ('mi_rest', (0, 1, 2, 3), (4,)),
    ('both_hands_rest', (2,), (4,)), ('right_hand_both_feet', (1,), (3,))])
def test_names_give_their_sides(name: str, yes: tuple, no: tuple) -> None:
    pair = answer_pair(name)
    assert (pair.yes, pair.no) == (yes, no)


def test_an_unknown_name_is_one_line_naming_the_forms() -> None:
    with pytest.raises(CommonError, match=r"Unknown answer pair 'hands_nose'; use auto, "
                                          r'hands_feet, left_right, mi_rest or two class names'):
        answer_pair('hands_nose')


def test_sides_must_be_disjoint() -> None:
    with pytest.raises(CommonError, match='two disjoint, non-empty sets'):
        AnswerPair('x', (2,), (2,))


def test_the_person_is_told_what_to_imagine() -> None:
    assert answer_pair('hands_feet').describe() == \
        'yes: imagine both hands; no: imagine both feet'
    assert answer_pair('mi_rest', (1, 0, 2, 3), (4,)).describe() == (
        'yes: imagine a movement (the right hand works best for you; any counts); '
        'no: rest (imagine nothing)')


def test_a_reversed_pair_round_trips_through_the_model_file(tmp_path: Path) -> None:
    pair = answer_pair('left_right', (1,), (0,))
    (tmp_path / 'm.json').write_text(json.dumps({
        'answer_pair': pair.to_dict(),
        'decision_thresholds': {'confirm': 2, 'pass': 2, 'affirm': 2, 'cancel': 3.5}}))
    chosen, thresholds = model_decision(tmp_path / 'm')
    assert chosen == pair and chosen.yes_class == 1 and chosen.no_class == 0
    assert thresholds == {'confirm': 2.0, 'pass': 2.0, 'affirm': 2.0, 'cancel': 3.5}
    (tmp_path / 'old.json').write_text('{}')
    assert model_decision(tmp_path / 'old.json') == (None, None)
    with pytest.raises(CommonError, match='Cannot read the classifier model'):
        model_decision(tmp_path / 'missing.json')
