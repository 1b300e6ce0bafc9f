"""Virtual amplifier: pacing, imagery onsets, and the ROS-free CLI as a real LSL source."""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import pylsl
import pytest

from mindgrasp_eeg.montage import NAUTILUS_32
from mindgrasp_eeg.subject import VirtualSubject
from mindgrasp_eeg.synthetic import SyntheticEEG
from mindgrasp_eeg.virtual_amp import VirtualAmplifier


def test_paced_by_the_given_clock() -> None:
    subject = VirtualSubject('follow', reaction_delay=0.0, seed=0)
    amp = VirtualAmplifier(SyntheticEEG(seed=0), subject, None, block=5)
    assert amp.step(100.0).shape == (0, 32)              # sample 0 is due, its block is not
    assert len(amp.step(100.5)) == 125                   # 126 due: 25 whole blocks of 5
    subject.on_prompt(101.0, 2, 'cue', 1)
    amp.step(102.0)
    assert amp.n_samples == 500 and amp.current_class == 2
    assert len(amp.step(102.0)) == 0                     # nothing new is due


def test_an_lsl_amplifier_sends_whole_blocks_only() -> None:
    """Pushes between block ends sent a partial block as a chunk of its own: /eeg/raw ran at
    38.6 chunks/s instead of 250 / 8 = 31.25."""
    amp = VirtualAmplifier(SyntheticEEG(seed=0), VirtualSubject('noise'), None, block=8)
    sizes = [len(amp.step(t)) for t in np.arange(0.0, 3.0, 1 / 32 + 0.0007)]
    assert sum(sizes) % 8 == 0 and all(n % 8 == 0 for n in sizes)
    assert sum(sizes) >= 3.0 * 250 - 2 * 8


def test_clock_jumps_re_anchor_in_simulated_time() -> None:
    amp = VirtualAmplifier(SyntheticEEG(seed=0), VirtualSubject('noise'), None,
                           realtime_stamps=False, max_catch_up=1.0)
    amp.step(0.0)
    assert len(amp.step(0.5)) == 125
    assert len(amp.step(100.0)) == 1                     # a jump ahead: no 100 s burst
    assert len(amp.step(100.2)) == 50
    assert len(amp.step(3.0)) == 1 and len(amp.step(3.1)) == 25   # a reset back in time
    assert amp.n_skipped > 20000


def test_same_seed_same_stream_whatever_the_pacing() -> None:
    a = VirtualAmplifier(SyntheticEEG(seed=3), VirtualSubject('noise'), None)
    b = VirtualAmplifier(SyntheticEEG(seed=3), VirtualSubject('noise'), None)
    xa = np.vstack([a.step(t) for t in np.arange(0, 2, 0.031)])
    xb = np.vstack([b.step(t) for t in np.arange(0, 2, 0.2)])
    n = min(len(xa), len(xb))
    np.testing.assert_allclose(xa[:n], xb[:n])


@pytest.mark.slow
def test_cli_without_ros_streams_labelled_eeg(stream_name) -> None:
    proc = subprocess.Popen([sys.executable, '-m', 'mindgrasp_cli', 'eeg', 'virtual-amp',
                             '--no-ros', '--cues', '1', '--name', stream_name],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        found = pylsl.resolve_byprop('name', stream_name, timeout=60)
        mk = pylsl.resolve_byprop('name', f'{stream_name}-markers', timeout=60)
        assert found and mk
        eeg, markers = pylsl.StreamInlet(found[0]), pylsl.StreamInlet(mk[0])
        info = eeg.info(timeout=30)
        ch = info.desc().child('channels').child('channel')
        labels, units = [], set()
        while not ch.empty():
            labels.append(ch.child_value('label'))
            units.add(ch.child_value('unit'))
            ch = ch.next_sibling('channel')
        assert labels == list(NAUTILUS_32) and units == {'microvolts'}
        assert info.nominal_srate() == 250.0
        got, end = [], time.monotonic() + 15
        while time.monotonic() < end and not any(g.startswith('cue/') for g in got):
            sample, _ts = markers.pull_sample(timeout=0.2)
            if sample:
                got.append(sample[0])
        data, _ = eeg.pull_chunk(timeout=1.0, max_samples=250, as_numpy=True)
    finally:
        proc.kill()
        proc.wait()
    assert got[0] in ('fixation', 'cue/left_hand', 'cue/right_hand', 'cue/both_hands',
                      'cue/both_feet') and any(g.startswith('cue/') for g in got)
    assert 3 < float(np.std(data)) < 50                   # microvolts on the wire
