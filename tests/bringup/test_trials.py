"""TrialPlanner: seeded targets, cycling, errors and the tally."""

import math

import pytest

from mindgrasp_bringup.trials import TrialOutcome, TrialPlanner
from mindgrasp_common.types import SceneObject

SCENE = [SceneObject(i, c, s) for i, (c, s) in enumerate(
    [('red', 'cube'), ('blue', 'cylinder'), ('yellow', 'sphere')])]


def test_random_targets_are_seeded():
    draws = []
    for _ in range(2):
        planner = TrialPlanner(seed=3)
        draws.append([planner.next_target(t, SCENE).label for t in range(1, 20)])
    assert draws[0] == draws[1] and len(set(draws[0])) == 3


def test_listed_targets_cycle_and_unknown_ones_are_named():
    planner = TrialPlanner(targets=['blue cylinder', 'red cube'])
    assert [planner.next_target(t, SCENE).label for t in (1, 2, 3)] == [
        'blue cylinder', 'red cube', 'blue cylinder']
    with pytest.raises(ValueError, match="Target 'green cone' is not in the scene; the scene has"):
        TrialPlanner(targets=['green cone']).next_target(1, SCENE)
    with pytest.raises(ValueError, match='no objects'):
        TrialPlanner().next_target(1, [])


def test_summary_counts_success_correctness_and_times():
    planner = TrialPlanner()
    planner.record(TrialOutcome(1, 'red cube', 'red cube', True, 10.0))
    planner.record(TrialOutcome(2, 'red cube', 'blue cylinder', True, 20.0))
    planner.record(TrialOutcome(3, 'red cube', '', False, 300.0, timed_out=True))
    s = planner.summary()
    assert s['trials'] == 3 and s['timeouts'] == 1
    assert math.isclose(s['success_rate'], 2 / 3) and math.isclose(s['correct_rate'], 1 / 3)
    assert s['mean_time_s'] == 15.0 and s['median_time_s'] == 15.0
