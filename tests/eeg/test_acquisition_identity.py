"""The acquisition keeps the sender it connected to first: a stream of the same name that
reappears from another source is refused, the first amplifier restarted is taken back (real LSL
outlets in other processes; issue 42)."""

from __future__ import annotations

import time

import pytest

from mindgrasp_eeg.acquisition import ERROR, OK, EEGAcquisition

pytestmark = pytest.mark.slow


def poll_until(acq: EEGAcquisition, condition, timeout: float = 60.0) -> bool:
    """Poll the acquisition until ``condition()`` holds or ``timeout`` s (a deadline, not a
    measure: a loaded machine answers late)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        acq.poll()
        if condition():
            return True
        time.sleep(0.05)
    return condition()


def test_a_stream_of_another_source_never_stands_in(lsl_source, stream_name) -> None:
    first = lsl_source(stream_name, '--source-id', 'amp-a', '--duration', '120')
    acq = EEGAcquisition(stream_name, lost_timeout=0.5)     # selected by name only
    desc = acq.connect(timeout=30)
    assert desc.identity[0] == 'amp-a' and acq.identity == desc.identity
    assert poll_until(acq, lambda: acq.counters['samples'] >= 250)
    first.kill()
    first.wait()
    assert poll_until(acq, lambda: acq.lost)
    # another rig (another source id) starts a stream of the same name: refused, named
    lsl_source(stream_name, '--source-id', 'amp-b', '--duration', '120')
    assert poll_until(acq, lambda: acq.counters['refused_streams'] >= 1), acq.status().message
    status = acq.status()
    assert not acq.connected and status.level == ERROR
    assert "source_id 'amp-b'" in status.message and "source_id 'amp-a'" in status.message
    assert 'accepts only that sender' in status.message
    assert len(acq.refusals) == 1 and "source_id 'amp-b'" in acq.refusals[0]
    before = acq.counters['samples']
    # the same amplifier restarted (a new outlet, a new uid, the same source): taken back
    lsl_source(stream_name, '--source-id', 'amp-a', '--duration', '120')
    assert poll_until(acq, lambda: acq.connected and acq.counters['samples'] > before + 125), \
        acq.status().message
    status = acq.status()
    assert status.level == OK and status.values['source_id'] == 'amp-a'
    assert acq.counters['reconnects'] >= 1 and acq.counters['refused_streams'] == 1
    acq.close()
