"""The participant's screen, composed as one RGB frame (ROS-free; the display node shows it).

Layouts follow the phase of the session::

    graz     the Graz-BCI cue (fixation cross, arrow) and the classifier's feedback bar, centred
    trainer  the third-person scene view (the user's robot and the green training robot) large,
             the eye-in-hand view with the vision overlay and the prompt/distance/state beside it
    test     the eye-in-hand view with the vision overlay large, the desired object, the scene view
             and the controller state beside it
    idle     "waiting" (and the scene view when there is one)

A banner on top names the phase and trial. Every frame is an ndarray of uint8, shape
(height, width, 3), RGB; the node blits it into a pygame window, or publishes it and writes PNG
files when headless, so tests read the same pixels a participant sees.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from mindgrasp_trainer.display import BAR_COLOUR, DIRECTIONS, FEEDBACK_MODES, render_display
from mindgrasp_trainer.protocol import CLASS_NAMES, NO_CLASS, PromptEvent, TrainerError

__all__ = ['LAYOUTS', 'ParticipantScreen', 'ScreenState', 'choose_layout']

LAYOUTS = ('auto', 'graz', 'trainer', 'test', 'idle')
BANNER_H = 44  # px
BACKGROUND = (18, 18, 24)
TEXT = (235, 235, 235)
DIM = (150, 150, 160)
#: what the participant is asked to do in a Trainer trial, per class
FOLLOW_TEXT = {0: 'turn left (left hand)', 1: 'turn right (right hand)',
               2: 'approach (both hands)', 3: 'back away (both feet)'}
#: rgb of the object colours named in /task/target
OBJECT_RGB = {'red': (220, 40, 40), 'blue': (40, 80, 230), 'yellow': (235, 210, 40)}
INSTRUCTION_COLOUR = (255, 220, 80)
PARADIGM_LABEL = {'graz': 'Graz-BCI', 'trainer': 'MIndGrasp Trainer', 'test': 'Test'}


def controller_instruction(paradigm: str, state: int, offered: bool = False,
                           yes_classes: Sequence[int] = (), no_classes: Sequence[int] = ()
                           ) -> str:
    """What the participant is asked to imagine now, from ``/fsm/state`` ('' = nothing to say).

    ``scan`` (mindgrasp_fsm.grasp_fsm): the arm offers objects; the person's answer pair
    (``FsmState.yes_classes`` / ``no_classes``, :mod:`mindgrasp_common.answer_pair`; none
    given: both hands / both feet) answers yes and no, and "no" cancels an approach.
    ``paper``: the four-class steering. Two lines (a heading and the classes), separated by a
    newline.
    """
    if paradigm == 'scan':
        yes, no = _answer_words(yes_classes, 'both hands'), _answer_words(no_classes, 'both feet')
        if offered:
            return f'Offered: want it?\n{yes} = yes, {no} = no'
        if state in (3, 4):
            return f'Approaching\n{yes} = go on, {no} = cancel'
        if state in (1, 2):
            return 'Searching\nrest'
        return 'Rest'
    if paradigm == 'paper' and state in (1, 2, 3):
        return 'Left/right hand: turn\nboth hands: select/approach, feet: back'
    return ''


def _answer_words(classes: Sequence[int], default: str) -> str:
    """How the display names one side of the answer pair: 'both hands', 'left hand', 'rest',
    'any movement' (the imagery classes)."""
    words = {0: 'left hand', 1: 'right hand', 2: 'both hands', 3: 'both feet', 4: 'rest'}
    if not len(classes):
        return default
    if len(classes) > 1:
        return 'any movement'
    return words.get(int(classes[0]), default)


@dataclass
class ScreenState:
    """Everything the screen shows; the node keeps it up to date from its topics.

    Attributes
    ----------
    prompt : PromptEvent or None
        Current phase of the cue protocol (``/trainer/prompt``).
    prediction : (class_index, certainty) or None
        Latest classifier output, None when older than the node's timeout.
    scene : ndarray of uint8, shape (h, w, 3), or None
        Third-person view (``/scene/image_raw``).
    camera : ndarray of uint8, shape (h, w, 3), or None
        Eye-in-hand view with the vision overlay (``/vision/overlay``).
    fsm_state_name : str
        Controller state (``/fsm/state``), '' when unknown.
    target : str
        Desired object, "<colour> <shape>" (``/task/target``), '' when none.
    target_trial : int
        Trial number of the desired object (test phases).
    ee_distance : float
        Distance between the two end-effectors (m), NaN when unknown.
    phase_label : str
        Name of the session phase for the banner ('' derives it from the prompt's paradigm).
    n_trials : int
        Trials planned in this phase (0 when unknown).
    instruction : str
        What to imagine now (:func:`controller_instruction`), '' when nothing.
    evidence : float
        The controller's evidence for the decision at hand as a fraction of its threshold
        (0..1; the scan paradigm's confirmation or cancel).
    """

    prompt: PromptEvent | None = None
    prediction: tuple[int, float] | None = None
    scene: np.ndarray | None = None
    camera: np.ndarray | None = None
    fsm_state_name: str = ''
    target: str = ''
    target_trial: int = 0
    ee_distance: float = math.nan
    phase_label: str = ''
    n_trials: int = 0
    instruction: str = ''
    evidence: float = 0.0


def choose_layout(layout: str, state: ScreenState) -> str:
    """The layout to draw: ``layout`` unless it is ``auto``, else from what the state holds."""
    if layout != 'auto':
        return layout
    if state.prompt is not None and state.prompt.paradigm in ('graz', 'trainer'):
        return state.prompt.paradigm
    if state.target:
        return 'test'
    return 'idle'


def _text(img: np.ndarray, text: str, org: tuple[int, int], scale: float = 0.7,
          colour: tuple[int, int, int] = TEXT, thick: int = 2) -> None:
    cv2.putText(img, text, org, cv2.FONT_HERSHEY_SIMPLEX, scale, colour, thick, cv2.LINE_AA)


def _paste(img: np.ndarray, src: np.ndarray | None, box: tuple[int, int, int, int],
           missing: str) -> tuple[int, int, int, int]:
    """Scale ``src`` (rgb) into ``box`` (x, y, w, h) keeping its aspect; return the used box."""
    x, y, w, h = box
    if src is None:
        cv2.rectangle(img, (x, y), (x + w - 1, y + h - 1), DIM, 1)
        _text(img, missing, (x + 10, y + h // 2), 0.55, DIM, 1)
        return box
    sh, sw = src.shape[:2]
    s = min(w / sw, h / sh)
    tw, th = max(1, int(sw * s)), max(1, int(sh * s))
    # nearest neighbour keeps the overlay's box edges crisp on a 128 px camera image
    scaled = cv2.resize(src, (tw, th), interpolation=cv2.INTER_NEAREST if s >= 1
                        else cv2.INTER_AREA)
    ox, oy = x + (w - tw) // 2, y + (h - th) // 2
    img[oy:oy + th, ox:ox + tw] = scaled
    return ox, oy, tw, th


class ParticipantScreen:
    """Composes the participant's frames.

    Parameters
    ----------
    width, height : int
        Frame size (px), at least 320 x 240.
    layout : {'auto', 'graz', 'trainer', 'test', 'idle'}
        Fixed layout, or ``auto`` to follow the prompts and targets.
    feedback : {'off', 'move', 'always'}
        When the Graz layout shows the feedback bar (see :func:`render_display`).
    max_certainty : float
        Certainty that fills the feedback bar.
    """

    def __init__(self, width: int = 1024, height: int = 600, layout: str = 'auto',
                 feedback: str = 'move', max_certainty: float = 1.0) -> None:
        if not (isinstance(width, (int, np.integer)) and isinstance(height, (int, np.integer))
                and width >= 320 and height >= 240):
            msg = (f'The display size {width}x{height} px is too small; use at least 320x240 '
                   'pixels (1024x600 by default).')
            raise TrainerError(msg)
        if layout not in LAYOUTS:
            msg = f"'layout' is {layout!r}; use one of {', '.join(LAYOUTS)}."
            raise TrainerError(msg)
        if feedback not in FEEDBACK_MODES:
            msg = f"'feedback' is {feedback!r}; use one of {', '.join(FEEDBACK_MODES)}."
            raise TrainerError(msg)
        if not (math.isfinite(max_certainty) and max_certainty > 0):
            msg = f"'max_certainty' must be a positive number; {max_certainty} is invalid."
            raise TrainerError(msg)
        self.width, self.height = int(width), int(height)
        self.layout = layout
        self.feedback = feedback
        self.max_certainty = float(max_certainty)
        self._blank: np.ndarray | None = None  # background, copied for each frame

    # ------------------------------------------------------------------ frame
    def render(self, state: ScreenState) -> np.ndarray:
        """One frame, ndarray of uint8, shape (height, width, 3), RGB."""
        if self._blank is None:
            self._blank = np.empty((self.height, self.width, 3), np.uint8)
            self._blank[:] = BACKGROUND
            self._blank[:BANNER_H] = (40, 40, 52)
        img = self._blank.copy()
        layout = choose_layout(self.layout, state)
        self._banner(img, state, layout)
        body = (0, BANNER_H, self.width, self.height - BANNER_H)
        getattr(self, f'_draw_{layout}')(img, state, body)
        return img

    def _banner(self, img: np.ndarray, state: ScreenState, layout: str) -> None:
        label = state.phase_label or PARADIGM_LABEL.get(layout, 'MIndGrasp')
        trial = state.prompt.trial if state.prompt is not None else state.target_trial
        if layout == 'test':
            trial = state.target_trial or trial
        parts = [label]
        if trial:
            parts.append(f'trial {trial}/{state.n_trials}' if state.n_trials else f'trial {trial}')
        if state.prompt is not None and state.prompt.phase == 'end':
            parts.append('finished')
        _text(img, ' - '.join(parts), (12, 30), 0.75)
        if state.fsm_state_name:
            text = f'controller: {state.fsm_state_name}'
            (tw, _), _ = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.6, 1)
            _text(img, text, (self.width - tw - 12, 29), 0.6, DIM, 1)

    def _draw_graz(self, img: np.ndarray, state: ScreenState, box: tuple) -> None:
        x, y, w, h = box
        side_h = h - 20
        side_w = min(w - 20, int(side_h * 4 / 3))
        panel = render_display(state.prompt, state.prediction, side_w, side_h, self.feedback,
                               self.max_certainty)
        ox = x + (w - side_w) // 2
        img[y + 10:y + 10 + side_h, ox:ox + side_w] = panel

    def _draw_trainer(self, img: np.ndarray, state: ScreenState, box: tuple) -> None:
        x, y, w, h = box
        left_w = int(w * 0.64)
        _paste(img, state.scene, (x + 10, y + 10, left_w - 20, h - 20),
               'no scene view (/scene/image_raw)')
        rx, rw = x + left_w, w - left_w - 10
        cam_h = min(rw * 3 // 4, h // 2)
        _paste(img, state.camera, (rx, y + 10, rw, cam_h), 'no camera view')
        ty = y + cam_h + 45
        p = state.prompt
        if p is not None and p.class_index != NO_CLASS and p.phase in ('move', 'wait'):
            _text(img, 'Follow the green robot:', (rx, ty), 0.6, DIM, 1)
            _text(img, FOLLOW_TEXT[p.class_index], (rx, ty + 32), 0.75, (60, 220, 80))
        elif p is not None and p.phase == 'rest':
            _text(img, 'Rest', (rx, ty + 32), 0.75)
        if math.isfinite(state.ee_distance):
            _text(img, f'distance {100 * state.ee_distance:.1f} cm', (rx, ty + 75), 0.65)
        self._mini_bar(img, state, (rx, ty + 95, rw, 26))

    def _draw_test(self, img: np.ndarray, state: ScreenState, box: tuple) -> None:
        x, y, w, h = box
        left_w = int(w * 0.6)
        _paste(img, state.camera, (x + 10, y + 10, left_w - 20, h - 20),
               'no camera view (/vision/overlay)')
        rx, rw = x + left_w, w - left_w - 10
        _text(img, 'Grasp:', (rx, y + 40), 0.65, DIM, 1)
        if state.target:
            colour = OBJECT_RGB.get(state.target.split()[0], TEXT)
            cv2.rectangle(img, (rx, y + 55), (rx + 34, y + 89), colour, -1)
            _text(img, state.target, (rx + 46, y + 82), 0.8)
        else:
            _text(img, '-', (rx, y + 82), 0.8)
        scene_y = y + 110
        scene_h = min(rw * 3 // 4, h - 250)
        _paste(img, state.scene, (rx, scene_y, rw, scene_h), 'no scene view')
        self._mini_bar(img, state, (rx, scene_y + scene_h + 12, rw, 26))
        if state.instruction:
            iy = scene_y + scene_h + 88
            for i, line in enumerate(state.instruction.split('\n')):
                _text(img, line, (rx, iy + 26 * i), 0.65 if i == 0 else 0.55,
                      INSTRUCTION_COLOUR, 2 if i == 0 else 1)
            frac = min(max(state.evidence, 0.0), 1.0)
            if frac > 0:        # the evidence for the decision at hand, of its threshold
                cv2.rectangle(img, (rx, iy + 40), (rx + int(rw * frac), iy + 48), BAR_COLOUR,
                              -1)

    def _draw_idle(self, img: np.ndarray, state: ScreenState, box: tuple) -> None:
        x, y, w, h = box
        if state.scene is not None:
            _paste(img, state.scene, (x + 10, y + 10, w - 20, h - 70), '')
        _text(img, 'Waiting for the session to start', (x + 20, y + h - 25), 0.8)

    def _mini_bar(self, img: np.ndarray, state: ScreenState, box: tuple) -> None:
        """The decoded class and its certainty as a short horizontal bar (robot phases)."""
        if state.prediction is None:
            return
        x, y, w, h = box
        k, certainty = state.prediction
        if k not in DIRECTIONS or not math.isfinite(certainty):
            return
        frac = min(max(certainty / self.max_certainty, 0.0), 1.0)
        cv2.rectangle(img, (x, y), (x + w - 1, y + h - 1), DIM, 1)
        if frac > 0:
            cv2.rectangle(img, (x + 1, y + 1), (x + 1 + int((w - 3) * frac), y + h - 2),
                          BAR_COLOUR, -1)
        _text(img, f'{CLASS_NAMES[k]} {certainty:.2f}', (x, y + h + 22), 0.55, TEXT, 1)
