"""CommandGate: the command timeout of the forward velocity controller, and a clock skip;
CommandBursts: one warning per burst of bad commands, and the hold after refused ones."""

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


def test_bad_commands_warn_once_per_burst_and_hold_until_clean() -> None:
    from mindgrasp_sim.control import CommandBursts

    bursts = CommandBursts(hold=1.0)
    assert not bursts.holding('refused', 0.0)
    # NaN at 20 Hz for 2 s: one warning, held all along and for 1 s after the last one
    starts = [bursts.bad('refused', 0.05 * k) for k in range(40)]
    assert starts == [True] + [False] * 39 and bursts.count['refused'] == 40
    assert bursts.holding('refused', 1.95 + 0.99) and not bursts.holding('refused', 1.95 + 1.0)
    assert bursts.bad('refused', 4.0)                   # a new burst, a new warning
    assert bursts.bad('clipped', 4.0)                   # kinds are counted apart
