"""The random-locations experiment: trial draws, determinism, the CLI and its JSON line."""

from __future__ import annotations

import argparse
import json
import math

import numpy as np
import pytest

from mindgrasp_bringup.commands import experiment_random_locations as cli
from mindgrasp_fsm.experiment import TrialSpec, build_loop, draw_trials
from mindgrasp_fsm.params import FsmParams


def test_draw_trials_is_seeded_balanced_and_in_range() -> None:
    a = draw_trials(30, seed=4)
    assert a == draw_trials(30, seed=4)
    assert a != draw_trials(30, seed=5)
    shapes = [t.shape for t in a]
    assert {s: shapes.count(s) for s in set(shapes)} == {'cube': 10, 'cylinder': 10, 'sphere': 10}
    assert all(0.2 <= t.radius <= 0.7 and -170 <= t.angle_deg <= 170 for t in a)
    assert all(0.04 <= t.size <= 0.06 for t in a)
    assert {t.colour for t in a} == {'red', 'yellow', 'blue'}


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    cli.add_arguments(parser)
    return parser.parse_args(argv)


def test_cli_rejects_bad_arguments(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(_parse(['--trials', '0'])) == 2
    assert '--trials must be >= 1' in capsys.readouterr().err
    assert cli.main(_parse(['--timeout', '-1'])) == 2
    assert '--timeout must be > 0' in capsys.readouterr().err
    assert cli.main(_parse(['--trials', '1', '--realism', 'realistic'])) == 2
    err = capsys.readouterr().err
    assert "--realism: Unknown realism profile 'realistic'; use one of ['default', 'none']" in err
    assert err.count('\n') == 1


def test_cli_bad_params_file(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / 'fsm.yaml'
    bad.write_text('fsm:\n  ros__parameters:\n    lock_duraton: 1.0\n')
    assert cli.main(_parse(['--trials', '1', '--params-file', str(bad)])) == 2
    assert "Unknown controller parameter(s) ['lock_duraton']" in capsys.readouterr().err


@pytest.mark.slow
def test_lockstep_is_deterministic() -> None:
    loop, _ = build_loop(FsmParams())
    try:
        finals = []
        for _ in range(2):
            loop.sim.load_scene(TrialSpec(0, 'cube', 'red', 0.4, 25.0, 0.05, 10.0).scene())
            out = loop.run(0, timeout=6.0)
            finals.append((loop.sim.joint_positions(), out.states))
    finally:
        loop.sim.close()
    np.testing.assert_array_equal(finals[0][0], finals[1][0])
    assert finals[0][1] == finals[1][1]


@pytest.mark.slow
def test_cli_one_trial_json(capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(_parse(['--trials', '1', '--seed', '2', '--json'])) == 0
    out = capsys.readouterr().out.strip().splitlines()
    summary = json.loads(out[-1])
    for key in ('trials', 'success_rate', 'success_by_shape', 'median_time_s',
                'real_time_factor'):
        assert key in summary
    assert summary['trials'] == 1
    assert set(summary['success_by_shape']) == {'cube', 'cylinder', 'sphere'}
    assert summary['success_rate'] == 1.0, out
    assert summary['real_time_factor'] > 0
    assert math.isfinite(summary['median_time_s'])
    assert any(line.startswith('  overall') for line in out)
