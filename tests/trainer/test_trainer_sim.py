"""TrainerProtocol driving the PyBullet training robot (mindgrasp_sim's ROS-free Simulation):
class directions in Cartesian space, the 0.1 m reset rule with real kinematics, the distance
metric."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_trainer.trainer import TrainerProtocol, ee_distance

pytestmark = pytest.mark.slow

CONTROL_HZ = 50


@pytest.fixture(scope='module')
def sim():
    from mindgrasp_sim.simulation import Simulation

    s = Simulation(trainer_robot=True)
    yield s
    s.close()


def test_each_class_moves_the_training_end_effector_its_way(sim):
    proto = TrainerProtocol()
    for k in range(4):
        sim.reset()
        p0 = sim.ee_pose('trainer')[0]
        sim.set_joint_velocities(proto.velocity(k), 'trainer')
        sim.step(int(2.0 * sim.physics_hz))  # the 2 s move
        sim.stop('trainer')
        p1 = sim.ee_pose('trainer')[0]
        yaw0, yaw1 = math.atan2(p0[1], p0[0]), math.atan2(p1[1], p1[0])
        r0, r1 = np.hypot(*p0[:2]), np.hypot(*p1[:2])
        if k == 0:  # left hand: the arm turns left (counter-clockwise seen from above)
            assert yaw1 - yaw0 == pytest.approx(0.4, abs=0.02)
        elif k == 1:  # right hand: turns right
            assert yaw1 - yaw0 == pytest.approx(-0.4, abs=0.02)
        elif k == 2:  # both hands: approach, forward and down towards the objects
            assert r1 - r0 > 0.02 and p1[2] - p0[2] < -0.02
            assert abs(yaw1 - yaw0) < 1e-3
        else:  # both feet: back away, backward and up
            assert r1 - r0 < -0.02 and p1[2] - p0[2] > 0.02
        # the user's robot is not touched by the trainer's commands
        np.testing.assert_allclose(sim.joint_positions('user'), sim.home_pose, atol=0.01)


def test_session_resets_below_0_1_m_and_measures_the_distance(sim):
    sim.reset()
    # a fast approach so that the 0.1 m rule fires within a short session
    proto = TrainerProtocol(n_trials=12, classes=(0, 2), approach_speed=0.4, seed=3,
                            settle_time=0.2)  # fmt: skip
    n_sub = int(sim.physics_hz / CONTROL_HZ)
    t = 0.0
    proto.start(t)
    resets, lowest, first_distances = [], [], []
    while not proto.done and t < 120.0:
        z = sim.ee_pose('trainer')[0][2]
        step = proto.update(t, z, fsm_state=1)
        d = ee_distance(sim.ee_pose('trainer')[0], sim.ee_pose('user')[0])
        if step.events and step.events[0].phase == 'move' and proto.trial.trial > 1:
            first_distances.append((proto.trial.trial, d))
        proto.record_distance(d)
        if step.reset:
            resets.append(step.reset)
            lowest.append(z)
            sim.reset()
            proto.reset_finished(t)
        else:
            sim.set_joint_velocities(step.command, 'trainer')
        sim.step(n_sub)
        t += n_sub / sim.physics_hz
    assert proto.done
    assert resets, 'the training end-effector never went below 0.1 m'
    assert all('below 0.100 m' in r for r in resets)
    # it fired within one control period of crossing (0.4 rad/s: a few mm per period)
    assert all(0.07 < z < 0.1 for z in lowest)
    # after a reset both robots are home again: their end-effectors coincide
    after_reset = {tr.trial + 1 for tr in proto.trials if tr.aborted}
    for trial, d in first_distances:
        if trial in after_reset:
            assert d < 0.005
    s = proto.summary()
    assert s['n_resets'] == len(resets) and s['mean_ee_distance'] > 0.05
    assert set(s['per_class_ee_distance']) == {'left_hand', 'both_hands'}
