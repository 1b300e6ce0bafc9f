"""The replay subject: real EEGMMIDB imagery epochs of the intended class, stitched with rest
(S001 runs from MNE_DATASETS_EEGBCI_PATH, ../shared/data), as a plain class and inside the
virtual amplifier node over DDS."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.replay_eeg import MIN_EPOCHS, ReplayEEG
from mindgrasp_eeg.subject_file import (
    EEGMMIDB_CALIBRATION_RUNS,
    EEGMMIDB_PLAY_RUNS,
    parse_replay_source,
)

from .test_nodes import Listener, _prompt
from .test_subject_file import EXAMPLE


@pytest.fixture(scope='module')
def replay() -> ReplayEEG:
    return ReplayEEG.from_source('eegmmidb:1', seed=0)


def test_calibration_and_played_runs_are_disjoint() -> None:
    assert not set(EEGMMIDB_CALIBRATION_RUNS) & set(EEGMMIDB_PLAY_RUNS)


def test_every_class_and_rest_have_real_epochs(replay: ReplayEEG) -> None:
    assert replay.sample_rate == 160.0 and replay.n_channels == 64
    assert {'C3', 'Cz', 'C4'} <= set(replay.channel_names)
    for cls in (None, 0, 1, 2, 3):
        assert len(replay.epochs[cls]) >= MIN_EPOCHS
        for epoch in replay.epochs[cls]:
            assert epoch.shape[1] == 64 and len(epoch) >= 160
            assert np.allclose(epoch.mean(axis=0), 0.0, atol=1e-12)   # no DC steps at joins
            assert 1e-6 < epoch.std() < 200e-6                         # EEG in volts


def test_an_intent_streams_whole_epochs_of_its_class_and_a_change_starts_a_new_one() -> None:
    gen = ReplayEEG.from_source('eegmmidb:1', seed=3)
    first = gen.generate(100, 2)                  # in 16-sample blocks, as the amplifier asks
    first = np.vstack([first, *(gen.generate(16, 2) for _ in range(20))])
    matches = [e for e in gen.epochs[2] if np.array_equal(e[:len(first)], first)]
    assert len(matches) == 1, 'the stream is not one recorded epoch of the intended class'
    switched = gen.generate(50, 3)
    assert any(np.array_equal(e[:50], switched) for e in gen.epochs[3])
    rest = gen.generate(50, None)
    assert any(np.array_equal(e[:50], rest) for e in gen.epochs[None])
    # an intent held past one epoch goes on with the next epoch of the same class
    long = gen.generate(3 * len(gen.epochs[0][0]), 0)
    assert gen.n_played[0] >= 3 and long.shape == (3 * len(gen.epochs[0][0]), 64)
    assert gen.n_generated == len(first) + 100 + len(long)


def test_same_seed_same_stream() -> None:
    a, b = (ReplayEEG.from_source('eegmmidb:1', seed=5) for _ in range(2))
    for cls in (0, None, 1, 1, 3):
        assert np.array_equal(a.generate(300, cls), b.generate(300, cls))


@pytest.mark.parametrize(('text', 'message'), [
    ('eegbci:1', 'write eegmmidb:<subject>'), ('eegmmidb:x', 'write eegmmidb:<subject>'),
    ('eegmmidb:200', 'EEGMMIDB has subjects 1-109')])
def test_bad_sources_are_named(text: str, message: str) -> None:
    with pytest.raises(EEGError, match=message):
        parse_replay_source(text)


def test_too_few_epochs_of_a_class_is_named(replay: ReplayEEG) -> None:
    epochs = {cls: eps[:1] if cls == 3 else eps for cls, eps in replay.epochs.items()}
    with pytest.raises(EEGError, match=r'1 recorded epoch\(s\) of class 3, fewer than 3'):
        ReplayEEG(epochs, 160.0, replay.channel_names, min_epochs=MIN_EPOCHS)


@pytest.mark.parametrize('source', ['eegmmidb:1', str(EXAMPLE)], ids=['eegmmidb', 'subject_file'])
def test_virtual_amp_node_streams_the_replay_over_dds(spawn_node, rclpy_ctx, replay: ReplayEEG,
                                                      source: str) -> None:
    """The virtual amplifier node (output:=ros) with eeg_source:=eegmmidb:1 or the same subject
    as a subject file streams the recordings' channels at their rate, and the follow subject's
    prompted intent."""
    listener = Listener(rclpy_ctx)
    try:
        spawn_node('mindgrasp_eeg.virtual_amp_node', '--ros-args', '-p', 'output:=ros', '-p',
                   f'eeg_source:={source}', '-p', 'subject_mode:=follow', '-p', 'accuracy:=1.0',
                   '-p', 'reaction_delay:=0.0')
        assert listener.spin(90, lambda: len(listener.chunks) > 5)
        listener.prompt_pub.publish(_prompt(listener))
        assert listener.spin(60, lambda: 'left_hand' in listener.intents), listener.intents
        assert listener.spin(60, lambda: sum(m.n_samples for _, m in listener.chunks) >= 320)
        msg = listener.chunks[-1][1]
        assert list(msg.channel_names) == replay.channel_names and msg.sample_rate == 160.0
        data = np.asarray(msg.data).reshape(msg.n_samples, 64)
        assert 1e-6 < data.std() < 200e-6
    finally:
        listener.node.destroy_node()
