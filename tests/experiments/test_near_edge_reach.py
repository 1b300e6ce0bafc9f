"""The Panda at the near edge of the random-locations scene (issue 28): random locations seed 0
trial 79 puts a yellow cube 0.20 m from the base axis, where the folded elbow has no vertical
pose above it; the controller leans the tool back towards the base and grasps it. Before, the
trial ended 'no inverse-kinematics solution above the object' (4 of seed 0's 90 trials).
The real experiment graph in lock-step (simulator, vision, controller, trial manager)."""

from __future__ import annotations

from pathlib import Path

import pytest

from mindgrasp_experiments.engine import run_trial
from mindgrasp_experiments.experiment import Experiment
from mindgrasp_experiments.subject_launch import subject_launch_args


@pytest.mark.slow
@pytest.mark.timeout(1800)   # a whole trial on a loaded machine
def test_the_panda_grasps_a_cube_at_the_near_edge(tmp_path: Path) -> None:
    exp = Experiment('random_locations', subject='autonomous', seed=0, robot='panda',
                     realism='default')
    comps = exp.components(tmp_path, subject_launch_args('autonomous', tmp_path),
                           log=lambda line: None)
    rec = run_trial(comps, 79, seed=0, log_level='warn').record
    assert rec.desired == 'yellow cube' and abs(rec.desired_x ** 2 + rec.desired_y ** 2
                                                 - 0.201 ** 2) < 0.01 ** 2
    assert rec.states == '1-2-3-4-5-6', (rec.states, rec.reason)
    assert rec.success and rec.correct_choice, rec.reason
