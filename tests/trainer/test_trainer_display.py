"""Graz screen rendering: cross, arrows and feedback bar where the class says."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_trainer.display import ARROW_COLOUR, BAR_COLOUR, render_display
from mindgrasp_trainer.protocol import NO_CLASS, PromptEvent, TrainerError

W, H = 320, 240


def ev(phase, k=NO_CLASS):
    return PromptEvent(0.0, phase, 1, k, 1.0, 'graz')


def mask(img, colour):
    return np.all(img == np.asarray(colour, np.uint8), axis=-1)


def centroid(m):
    ys, xs = np.nonzero(m)
    return xs.mean() - W / 2, ys.mean() - H / 2


def test_blank_before_first_prompt_and_during_rest():
    assert not render_display(None, width=W, height=H).any()
    assert not render_display(ev('rest'), width=W, height=H).any()


def test_fixation_cross_is_white_and_centred():
    img = render_display(ev('fixation'), width=W, height=H)
    assert img.shape == (H, W, 3) and img.dtype == np.uint8
    white = mask(img, (255, 255, 255))
    assert white.sum() > 100
    x, y = centroid(white)
    assert abs(x) < 2 and abs(y) < 2


@pytest.mark.parametrize(('k', 'direction'), [(0, (-1, 0)), (1, (1, 0)), (2, (0, -1)), (3, (0, 1))])
def test_arrow_points_in_class_direction(k, direction):
    img = render_display(ev('cue', k), width=W, height=H)
    red = mask(img, ARROW_COLOUR)
    assert red.sum() > 200
    x, y = centroid(red)
    assert np.sign(round(x / 10)) == direction[0] and np.sign(round(y / 10)) == direction[1]


@pytest.mark.parametrize(('k', 'direction'), [(0, (-1, 0)), (1, (1, 0)), (2, (0, -1)), (3, (0, 1))])
def test_feedback_bar_direction_and_length(k, direction):
    small = mask(render_display(ev('move', 1), (k, 0.3), width=W, height=H), BAR_COLOUR)
    big = mask(render_display(ev('move', 1), (k, 0.9), width=W, height=H), BAR_COLOUR)
    assert big.sum() > 2 * small.sum() > 0
    # ignore the text line at the bottom
    big[H - 30 :] = False
    x, y = centroid(big)
    assert np.sign(round(x / 10)) == direction[0] and np.sign(round(y / 10)) == direction[1]


def test_feedback_modes_and_clipping():
    pred = (1, 5.0)
    assert not mask(render_display(ev('fixation'), pred, width=W, height=H), BAR_COLOUR).any()
    assert mask(render_display(ev('fixation'), pred, W, H, feedback='always'), BAR_COLOUR).any()
    assert not mask(render_display(ev('move', 1), pred, W, H, feedback='off'), BAR_COLOUR).any()
    clipped = render_display(ev('move', 1), pred, W, H)
    assert not mask(clipped, BAR_COLOUR)[: H - 30, W - 4 :].any()  # stays inside the frame


@pytest.mark.parametrize(
    ('kwargs', 'match'),
    [
        ({'width': 10}, 'display size 10x240 px is too small'),
        ({'feedback': 'sometimes'}, "'feedback' is 'sometimes'; use one of off, move, always"),
        ({'max_certainty': 0.0}, "'max_certainty' must be a positive number"),
    ],
)
def test_bad_display_parameters(kwargs, match):
    args = {'width': W, 'height': H} | kwargs
    with pytest.raises(TrainerError, match=match):
        render_display(ev('cue', 0), **args)
