"""The participant's screen composed by ParticipantScreen: layouts by phase, checked by pixels."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_trainer.display import ARROW_COLOUR, BAR_COLOUR
from mindgrasp_trainer.protocol import PromptEvent, TrainerError
from mindgrasp_trainer.screen import BANNER_H, ParticipantScreen, ScreenState, choose_layout


def count(img: np.ndarray, rgb: tuple[int, int, int], tol: int = 12) -> int:
    return int(np.count_nonzero(np.all(np.abs(img.astype(int) - rgb) <= tol, axis=2)))


def test_graz_layout_draws_the_arrow_then_the_feedback_bar():
    screen = ParticipantScreen(800, 480, feedback='move')
    cue = ScreenState(prompt=PromptEvent(0.0, 'cue', 3, 1, 1.25, 'graz'), n_trials=40)
    img = screen.render(cue)
    assert img.shape == (480, 800, 3) and img.dtype == np.uint8
    assert choose_layout('auto', cue) == 'graz'
    _ys, xs = np.nonzero(np.all(np.abs(img.astype(int) - ARROW_COLOUR) <= 12, axis=2))
    assert len(xs) > 200 and xs.mean() > 400          # right hand: the arrow points right
    move = ScreenState(prompt=PromptEvent(1.25, 'move', 3, 1, 2.75, 'graz'),
                       prediction=(1, 0.8))
    img = screen.render(move)
    _ys, xs = np.nonzero(np.all(np.abs(img.astype(int) - BAR_COLOUR) <= 12, axis=2))
    assert len(xs) > 200 and np.median(xs) > 400      # the bar grows to the right
    assert count(img, ARROW_COLOUR) == 0               # the arrow is gone after the cue


def test_trainer_layout_shows_the_scene_large_and_the_camera_beside_it():
    scene = np.zeros((240, 320, 3), np.uint8)
    scene[100:140, 100:220] = (30, 200, 40)             # stand-in for the training robot
    camera = np.full((128, 128, 3), 90, np.uint8)
    state = ScreenState(prompt=PromptEvent(0.0, 'move', 1, 0, 2.0, 'trainer'), scene=scene,
                        camera=camera, ee_distance=0.123)
    img = ParticipantScreen(1024, 600).render(state)
    _ys, xs = np.nonzero(np.all(img == (30, 200, 40), axis=2))
    assert len(xs) > 4000 and xs.max() < 0.65 * 1024    # scene on the left, scaled up
    assert count(img, (90, 90, 90), 0) > 5000           # the camera view on the right


def test_test_layout_shows_the_camera_overlay_and_the_desired_object():
    camera = np.full((128, 128, 3), 60, np.uint8)
    camera[40:80, 40:80] = (200, 30, 30)
    camera[38:82, 38] = camera[38:82, 81] = (0, 255, 0)   # the overlay's green box
    camera[38, 38:82] = camera[81, 38:82] = (0, 255, 0)
    state = ScreenState(camera=camera, target='red cube', target_trial=2, n_trials=20,
                        fsm_state_name='OBJECT_SEARCH')
    assert choose_layout('auto', state) == 'test'
    img = ParticipantScreen(1024, 600).render(state)
    ys, xs = np.nonzero(np.all(img == (0, 255, 0), axis=2))
    assert len(xs) > 400 and xs.max() < 0.6 * 1024 and ys.min() > BANNER_H
    assert count(img, (220, 40, 40), 0) >= 34 * 34       # the red swatch of the desired object


def test_bad_settings_name_the_fix():
    with pytest.raises(TrainerError, match='at least 320x240'):
        ParticipantScreen(100, 100)
    with pytest.raises(TrainerError, match="'layout' is 'bogus'"):
        ParticipantScreen(layout='bogus')
    with pytest.raises(TrainerError, match="'feedback' is 'x'"):
        ParticipantScreen(feedback='x')
