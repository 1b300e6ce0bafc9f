"""Closed loop in the PyBullet simulator (lock-step): the controller grasps real objects.

- An oracle BCI that always sends the right class grasps the desired object among the nine of the
  set-locations scene (one object per shape).
- Autonomous mode (no BCI) grasps each shape at a random placement.
- A kinematic loop (no physics) checks the depth/IK placement geometry alone.
"""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_fsm.experiment import TrialSpec, build_loop
from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.lockstep import LockstepLoop, OracleBci
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import FsmInputs, GripperState, JointStateIn, State

from .conftest import CAMERA, HOME, PointObject, project


@pytest.fixture(scope='module')
def set_locations_loop():
    from mindgrasp_sim.simulation import Simulation
    from mindgrasp_vision.config import VisionConfig

    cfg = VisionConfig()
    try:
        classifier = cfg.load_classifier()
    except Exception:
        classifier = None
    sim = Simulation(scene='set_locations', seed=0)
    # a shorter lock than the default keeps the test quick; the behaviour is the same
    loop = LockstepLoop(sim, cfg.build_pipeline(classifier),
                        GraspFsm.from_params(FsmParams(lock_duration=0.5)))
    yield loop
    sim.close()


@pytest.mark.slow
@pytest.mark.parametrize('label', ['blue cylinder', 'yellow sphere', 'yellow cube'])
def test_oracle_bci_grasps_the_desired_object(set_locations_loop: LockstepLoop, label: str
                                              ) -> None:
    loop = set_locations_loop
    loop.sim.reset()
    target = next(o.object_id for o in loop.sim.objects() if o.label == label)
    out = loop.run(target, timeout=90.0, oracle=OracleBci(target))
    assert out.success, (out.reason, out.states)
    assert out.grasped_object == label
    assert out.states[:6] == [1, 2, 3, 4, 5, 6]
    # back in Object Search (the subject may select again at once: state 2 in the same tick)
    assert 'returned to the start position' in out.reason


@pytest.mark.slow
@pytest.mark.parametrize(('shape', 'radius', 'angle'), [('cube', 0.62, 35.0),
                                                        ('cylinder', 0.25, -60.0),
                                                        ('sphere', 0.45, 120.0)])
def test_autonomous_grasp_succeeds_for_each_shape(shape: str, radius: float, angle: float
                                                  ) -> None:
    loop, _ = build_loop(FsmParams(lock_duration=0.5))
    try:
        spec = TrialSpec(0, shape, 'yellow', radius, angle, 0.05, 20.0)
        loop.sim.load_scene(spec.scene())
        out = loop.run(0, timeout=90.0)
    finally:
        loop.sim.close()
    assert out.success, (out.reason, out.states)
    assert out.lift_height > 0.2
    assert out.states == [1, 2, 3, 4, 5, 6, 1]


@pytest.mark.slow
@pytest.mark.parametrize(('shape', 'radius', 'angle', 'seed'), [('cube', 0.45, 60.0, 1),
                                                                ('cylinder', 0.6, -100.0, 2),
                                                                ('sphere', 0.3, 150.0, 3)])
def test_autonomous_grasp_with_the_default_realism_profile(shape: str, radius: float,
                                                           angle: float, seed: int) -> None:
    """Noisy depth with invalid pixels, a miscalibrated camera, encoder noise, a lagging arm,
    an object of other mass/friction/size/hue, contacts on any surface: the grasp still works."""
    loop, _ = build_loop(FsmParams(lock_duration=0.5), realism='default', realism_seed=seed)
    try:
        spec = TrialSpec(0, shape, 'blue', radius, angle, 0.05, -30.0)
        loop.sim.load_scene(spec.scene())
        assert loop.sim.realism.enabled and np.isnan(loop.sim.render_camera()[1]).any()
        out = loop.run(0, timeout=90.0)
    finally:
        loop.sim.close()
    assert out.success, (out.reason, out.states)
    assert out.lift_height > 0.2


def test_kinematic_loop_places_the_gripper_on_the_object() -> None:
    """Pinhole camera + kinematic arm: search, centre, approach, descend onto a point object."""
    params = FsmParams(autonomous=True, lock_duration=0.3)
    fsm = GraspFsm.from_params(params)
    obj = PointObject(0.35, 0.30, 0.05)
    q = HOME.copy()
    dt = 0.02
    t = 0.0
    reached = None
    vision = None
    held = False
    closure = 0.0
    while t < 60.0:
        if round(t / dt) % 5 == 0:
            vision = project(fsm, q, obj, t)
        tool = fsm.kinematics.tool_position(q)
        at_object = np.linalg.norm(tool[:2] - obj.centre[:2]) < 0.012 and tool[2] < 0.06
        held = closure > 0.5 and (held or at_object)    # closed on the object: it stays held
        opening = 0.6 if held else 1.0 - closure
        gripper = GripperState(opening, np.nan, t, held)
        out = fsm.tick(FsmInputs(t, JointStateIn(q, np.zeros(6), t), None, vision, gripper,
                                 CAMERA))
        closure = out.gripper.position
        if out.state == State.GRASP_OBJECT and reached is None:
            reached = tool
        q = q + out.joint_velocities * dt
        t += dt
        if fsm.outcome and out.state == State.OBJECT_SEARCH:
            break
    assert reached is not None
    assert np.linalg.norm(reached[:2] - obj.centre[:2]) < 0.01
    assert fsm.outcome == 'holding'
