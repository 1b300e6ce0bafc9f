"""A kinematic loop (no physics) checks the controller's depth/IK placement geometry alone.

The closed loop through the simulator runs through the nodes in lock-step
(tests/experiments: the oracle subject grasps the desired object, the autonomous controller
grasps at random locations).
"""

from __future__ import annotations

import numpy as np

from mindgrasp_fsm.grasp_fsm import GraspFsm
from mindgrasp_fsm.params import FsmParams
from mindgrasp_fsm.types import FsmInputs, GripperState, JointStateIn, State

from .conftest import CAMERA, HOME, PointObject, project


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
