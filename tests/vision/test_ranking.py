"""Object-of-interest ranking: centre and size, left/right shifts, hysteresis."""

from __future__ import annotations

import pytest

from mindgrasp_vision import LEFT_HAND, RIGHT_HAND, Detection, ObjectOfInterestRanker, VisionError

W, H = 128, 128


def det(colour: str, cx: float, cy: float = 64.0, size: int = 10) -> Detection:
    x, y = round(cx - (size - 1) / 2), round(cy - (size - 1) / 2)
    count = size * size
    return Detection(colour=colour, bbox=(x, y, size, size), centre=(cx, cy),
                     pixel_count=count, pixel_fraction=count / (W * H))


def test_score_is_the_original_formula():
    r = ObjectOfInterestRanker()
    d = det('red', 64 + 30, 64 + 40)
    assert r.score(d, W, H) == pytest.approx(5 * d.pixel_fraction - 50 / W)


def test_prefers_the_object_nearest_the_centre():
    dets = [det('red', 20), det('blue', 70), det('yellow', 120)]
    assert ObjectOfInterestRanker().rank(dets, W, H) == 1
    assert [d.is_object_of_interest for d in dets] == [False, True, False]
    assert dets[1].score > dets[0].score and dets[1].score > dets[2].score


def test_size_outweighs_a_small_offset():
    dets = [det('red', 70, size=8), det('blue', 85, size=60)]
    assert ObjectOfInterestRanker().rank(dets, W, H) == 1


@pytest.mark.parametrize(('mi_class', 'expected'), [
    (None, 'blue'), (LEFT_HAND, 'red'), (RIGHT_HAND, 'yellow'), (2, 'blue'), (3, 'blue')])
def test_left_right_prediction_shifts_the_focus(mi_class, expected):
    dets = [det('red', 32), det('blue', 64), det('yellow', 96)]
    r = ObjectOfInterestRanker(switch_frames=1)
    i = r.rank(dets, W, H, mi_class)
    assert dets[i].colour == expected
    assert r.focus(W, H, mi_class)[0] == {LEFT_HAND: 32, RIGHT_HAND: 96}.get(mi_class, 64)


def test_left_prediction_moves_the_choice_after_switch_frames():
    r = ObjectOfInterestRanker(switch_frames=3)
    frames = [r.rank([det('red', 32), det('blue', 64)], W, H) for _ in range(2)]
    assert frames == [1, 1]
    chosen = [r.rank([det('red', 32), det('blue', 64)], W, H, LEFT_HAND) for _ in range(4)]
    assert chosen == [1, 1, 0, 0]   # the left object wins from the third frame on
    # when the prediction ends, the centre object needs switch_frames frames to win back
    after = [r.rank([det('red', 32), det('blue', 64)], W, H) for _ in range(3)]
    assert after == [0, 0, 1]


def test_hysteresis_prevents_flicker_between_similar_objects():
    r = ObjectOfInterestRanker(hysteresis=0.05, switch_frames=3)
    flicker = ObjectOfInterestRanker(hysteresis=0.0, switch_frames=1)
    chosen, naive = [], []
    for k in range(20):
        # two equal objects either side of the centre, the better one alternating with noise
        jitter = 2.0 if k % 2 else -2.0
        frame = [det('red', 54 + jitter), det('blue', 74 + jitter)]
        chosen.append(frame[r.rank(frame, W, H)].colour)
        frame = [det('red', 54 + jitter), det('blue', 74 + jitter)]
        naive.append(frame[flicker.rank(frame, W, H)].colour)
    assert len(set(chosen)) == 1
    assert len(set(naive)) == 2   # without hysteresis the choice flickers


def test_a_clearly_better_object_takes_over():
    r = ObjectOfInterestRanker(hysteresis=0.05, switch_frames=2)
    assert r.rank([det('red', 64), det('blue', 110)], W, H) == 0
    # the camera turns: red moves off-centre (a tracked move), blue comes in
    picks = [r.rank([det('red', 50), det('blue', 66)], W, H) for _ in range(3)]
    assert picks == [0, 1, 1]


def test_tracks_the_object_as_it_moves_and_forgets_it_when_lost():
    r = ObjectOfInterestRanker(lost_frames=2)
    assert r.rank([det('red', 60)], W, H) == 0
    first = r.track_id
    for cx in (62, 66, 70):
        assert r.rank([det('red', cx), det('blue', 110)], W, H) == 0
    assert r.track_id == first
    for _ in range(3):
        assert r.rank([], W, H) is None
    assert r.rank([det('blue', 110), det('red', 20)], W, H) is not None
    assert r.track_id != first


def test_reset_forgets_the_choice():
    r = ObjectOfInterestRanker(switch_frames=5)
    r.rank([det('red', 64), det('blue', 100)], W, H)
    r.reset()
    assert r.rank([det('red', 20), det('blue', 64)], W, H) == 1


@pytest.mark.parametrize(('kwargs', 'match'), [
    ({'size_weight': -1}, "'size_weight' must be >= 0"),
    ({'hysteresis': -0.1}, "'hysteresis' must be >= 0"),
    ({'switch_frames': 0}, "'switch_frames' must be >= 1"),
    ({'match_radius': 0}, r"'match_radius' must be in \(0, 1\]"),
])
def test_bad_parameters(kwargs, match):
    with pytest.raises(VisionError, match=match):
        ObjectOfInterestRanker(**kwargs)


def test_bad_image_size():
    with pytest.raises(VisionError, match='image size must be positive'):
        ObjectOfInterestRanker().rank([det('red', 10)], 0, 128)
