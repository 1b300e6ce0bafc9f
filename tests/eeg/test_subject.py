"""Virtual subject: follow accuracy, lapses, delay; noise mode; pursue decisions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_common.types import SceneObject
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.montage import BOTH_FEET, BOTH_HANDS
from mindgrasp_eeg.subject import VirtualSubject, pursue_class
from mindgrasp_eeg.synthetic import SyntheticEEG

FS = 250.0


def run_prompts(subject: VirtualSubject, n_trials: int, seed: int = 0):
    """Graz-like trials: fixation 1 s, cue 3 s, rest 1 s. Returns (prompted, imagined at 2 s)."""
    rng = np.random.default_rng(seed)
    prompted, imagined = [], []
    t = 0.0
    for trial in range(1, n_trials + 1):
        cls = int(rng.integers(0, 4))
        subject.on_prompt(t, 255, 'fixation', trial)
        subject.on_prompt(t + 1.0, cls, 'cue', trial)
        prompted.append(cls)
        imagined.append(subject.intent(t + 2.0))
        subject.intent(t + 4.9)
        t += 5.0
    return np.array(prompted), imagined


@pytest.mark.parametrize('accuracy', [1.0, 0.7, 0.4])
def test_follow_accuracy_is_respected(accuracy: float) -> None:
    subject = VirtualSubject('follow', accuracy=accuracy, reaction_delay=0.3, seed=1)
    prompted, imagined = run_prompts(subject, 600)
    hits = np.mean([p == i for p, i in zip(prompted, imagined, strict=True)])
    assert hits == pytest.approx(accuracy, abs=0.06)
    assert all(i is not None for i in imagined)


def test_follow_lapses_and_reaction_delay() -> None:
    subject = VirtualSubject('follow', lapse_rate=0.25, reaction_delay=0.8, seed=2)
    _, imagined = run_prompts(subject, 400)
    assert np.mean([i is None for i in imagined]) == pytest.approx(0.25, abs=0.06)
    s = VirtualSubject('follow', reaction_delay=0.8, seed=0)
    s.on_prompt(10.0, 1, 'cue', 1)
    assert s.intent(10.7) is None and s.intent(10.81) == 1
    s.on_prompt(13.0, 255, 'rest', 1)
    assert s.intent(13.5) == 1 and s.intent(13.9) is None


def test_same_seed_same_decisions() -> None:
    a = run_prompts(VirtualSubject('follow', accuracy=0.6, seed=9), 50)[1]
    b = run_prompts(VirtualSubject('follow', accuracy=0.6, seed=9), 50)[1]
    assert a == b


def test_noise_mode_never_imagines() -> None:
    _, imagined = run_prompts(VirtualSubject('noise', seed=1), 50)
    assert imagined == [None] * 50


def class_info_accuracy(mode: str) -> float:
    """Cross-validated MDM accuracy on 2 s epochs labelled by the prompt."""
    from pyriemann.classification import MDM
    from pyriemann.estimation import Covariances
    from sklearn.model_selection import cross_val_score
    from sklearn.pipeline import make_pipeline
    from threadpoolctl import threadpool_limits

    subject = VirtualSubject(mode, accuracy=1.0, reaction_delay=0.0, seed=3)
    gen = SyntheticEEG(seed=4)
    rng = np.random.default_rng(5)
    epochs, y = [], []
    for trial in range(1, 121):
        cls = int(rng.integers(0, 4))
        subject.on_prompt(trial * 4.0, cls, 'cue', trial)
        gen.generate(int(0.5 * FS), subject.intent(trial * 4.0))      # ERD onset
        epochs.append(gen.generate(int(2 * FS), subject.intent(trial * 4.0 + 0.5)).T)
        subject.on_prompt(trial * 4.0 + 2.5, 255, 'rest', trial)
        gen.generate(int(1.5 * FS), subject.intent(trial * 4.0 + 2.5))
        y.append(cls)
    pipe = make_pipeline(Covariances('oas'), MDM())
    with threadpool_limits(1):            # BLAS threads oversubscribe a shared 2-core machine
        return float(cross_val_score(pipe, np.array(epochs) * 1e6, np.array(y), cv=4).mean())


@pytest.mark.slow
def test_noise_mode_carries_no_class_information_follow_does() -> None:
    assert class_info_accuracy('noise') < 0.4            # chance = 0.25
    assert class_info_accuracy('follow') > 0.6            # broadband MDM, 90 training epochs


def test_pursue_class_like_a_competent_user() -> None:
    left = SceneObject(1, 'blue', 'cylinder', (0.5 * math.cos(0.7), 0.5 * math.sin(0.7), 0.0))
    ahead = SceneObject(2, 'red', 'cube', (0.5, 0.0, 0.0))
    assert pursue_class(left, 0.0, 1) == 0                     # turn left towards it
    assert pursue_class(left, 1.4, 1) == 1                     # overshot: turn right
    assert pursue_class(left, 0.68, 1) == 2                    # centred: stop and approach
    assert pursue_class(ahead, 0.0, 3) == 2                    # approach the right one
    assert pursue_class(left, 0.0, 3, 'blue unknown') == 2     # shape not named yet: same colour
    assert pursue_class(ahead, 0.0, 3, 'blue unknown') == 3    # another colour: back away
    assert pursue_class(ahead, 0.0, 3, 'blue cylinder') == 3   # wrong object: back away
    assert pursue_class(ahead, 0.0, 2, 'blue cylinder') == 3
    assert pursue_class(ahead, 0.0, 2, 'red cube') is None     # centring is autonomous
    assert pursue_class(ahead, 0.0, 4) is None
    assert pursue_class(None, 0.0, 1) is None
    # the arm held still (after a prediction loss it waits for a fresh command): go on
    assert pursue_class(ahead, 0.0, 4, stopped=True) == 2
    assert pursue_class(ahead, 0.0, 2, 'red cube', stopped=True) == 2
    assert pursue_class(ahead, 0.0, 2, 'blue cylinder', stopped=True) == 3
    assert pursue_class(left, 0.0, 1, stopped=True) == 0
    assert pursue_class(None, 0.0, 4, stopped=True) is None
    # angles wrap: target at +170 deg seen from -170 deg is 20 deg to the right
    back = SceneObject(3, 'red', 'sphere',
                       (math.cos(math.radians(170)), math.sin(math.radians(170)), 0.0))
    assert pursue_class(back, math.radians(-170), 1) == 1


def test_pursue_mode_uses_its_inputs_and_accuracy() -> None:
    s = VirtualSubject('pursue', reaction_delay=0.2, decision_period=0.5, seed=0)
    s.set_objects([SceneObject(7, 'yellow', 'sphere', (0.0, 0.5, 0.0))])
    s.set_target(7, 'yellow', 'sphere')
    s.set_fsm(1)
    s.intent(0.0)
    assert s.intent(0.25) == 0                                 # target at +90 deg: left
    s.set_base_yaw(math.pi / 2)
    s.intent(0.5)
    assert s.intent(0.75) == 2
    noisy = VirtualSubject('pursue', accuracy=0.5, decision_period=0.1, seed=1)
    noisy.set_objects([SceneObject(7, 'yellow', 'sphere', (0.0, 0.5, 0.0))])
    noisy.set_target(7, '', '')
    for k in range(1000):
        noisy.intent(k * 0.1)
    right = np.mean([a == c for _, a, c in noisy.decisions])
    assert right == pytest.approx(0.5, abs=0.06)


def test_pursue_aims_at_a_new_target_before_it_selects() -> None:
    """A new target cancels the both-hands imagery meant for the object in front: the subject
    rests, then turns towards the new target (a 6-trial live run once selected the object in
    front 0.3 s after a new target appeared)."""
    ahead = SceneObject(0, 'red', 'cube', (0.5, 0.0, 0.0))
    left = SceneObject(1, 'blue', 'cylinder', (0.5 * math.cos(0.7), 0.5 * math.sin(0.7), 0.0))
    s = VirtualSubject('pursue', reaction_delay=0.5, decision_period=0.5, seed=0)
    s.set_objects([ahead, left])
    s.set_fsm(1)
    s.set_target(0, 'red', 'cube')
    s.intent(10.0)                          # decides both hands (it faces the red cube) ...
    assert s.intent(10.45) is None
    s.set_target(1, 'blue', 'cylinder')     # ... but the target changes before that starts
    imagined = [s.intent(10.5 + 0.01 * k) for k in range(60)]
    assert 2 not in imagined                # never both hands while facing the wrong object
    assert imagined[0] is None and imagined[-1] == 0      # rest, then turn left to the target


def test_bad_parameters() -> None:
    with pytest.raises(EEGError, match='mode must be one of'):
        VirtualSubject('dream')
    with pytest.raises(EEGError, match=r"accuracy must be within 0\.\.1"):
        VirtualSubject('follow', accuracy=1.5)


def test_a_subject_watching_the_jaco_reads_its_heading_from_the_robot_model():
    """The Jaco's first joint sits at 2.93 rad at home and turns clockwise for a positive angle:
    its raw angle as the heading made the virtual subject answer yes to the wrong objects (2 of
    30 correct, 24 wrong). With the robot's model it says yes to the object the arm faces."""
    from mindgrasp_eeg.subject import scan_class, subject_heading

    ahead = SceneObject(2, 'red', 'cube', (0.5, 0.0, 0.0))
    left = SceneObject(1, 'blue', 'cylinder', (0.5 * math.cos(0.7), 0.5 * math.sin(0.7), 0.0))
    heading = subject_heading('jaco')
    home = heading.home
    assert heading.joint == 'j2n6s300_joint_1'

    def answer(target: SceneObject, angle: float) -> int | None:
        return scan_class(target, heading(angle), 1, offered=True)

    assert answer(ahead, home) == BOTH_HANDS and answer(left, home) == BOTH_FEET
    # turned left (counter-clockwise from above) by 0.7 rad: the Jaco's angle goes down
    assert answer(left, home - 0.7) == BOTH_HANDS and answer(ahead, home - 0.7) == BOTH_FEET
    # the shipped arm's angle is its heading; a joint named explicitly is the one read
    assert subject_heading('')(0.3) == 0.3 and subject_heading('', 'joint_1').joint == 'joint_1'
    assert subject_heading('jaco', 'other').joint == 'other'


def test_a_subject_with_an_unknown_robot_says_so_in_one_line():
    from mindgrasp_common.robot_description import RobotDescriptionError
    from mindgrasp_eeg.subject import subject_heading

    with pytest.raises(RobotDescriptionError, match='no_such_arm'):
        subject_heading('no_such_arm')
