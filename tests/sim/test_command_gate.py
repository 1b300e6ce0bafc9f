"""CommandGate: the command timeout of the forward velocity controller, and a clock skip."""

from __future__ import annotations

import numpy as np

from mindgrasp_sim.control import CommandGate


def test_a_command_stays_fresh_across_a_clock_skip():
    gate = CommandGate(timeout=0.25)
    gate.command([0.3, 0, 0, 0, 0, 0], now=10.0)
    # the realtime loop skips 0.7 s of lag ahead: without the shift the command would be stale
    assert not np.any(gate.current(10.8))
    gate.command([0.3, 0, 0, 0, 0, 0], now=10.0)
    gate.shift(0.7)
    np.testing.assert_array_equal(gate.current(10.8), [0.3, 0, 0, 0, 0, 0])
    assert not np.any(gate.current(11.0))    # and it still times out 0.25 s later
