"""End to end: the trainer node drives the PyBullet training robot of the real simulator node
(two processes over DDS): class directions on the robot's joints, the 0.1 m reset through
/sim/reset, and the distance between the two end-effectors."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.slow


def test_trainer_drives_the_simulated_training_robot(ros, make_node, spawn_node, spin_until):
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt
    from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState
    from mindgrasp_ros.interfaces.std_msgs.msg import Float64

    node = make_node('trainer_sim_observer')
    joints: list[np.ndarray] = []      # joint positions (rad) in order of arrival
    prompts, distances = [], []        # (prompt, joint states received before it)
    tl = ros.qos.QoSProfile(
        depth=10,
        reliability=ros.qos.ReliabilityPolicy.RELIABLE,
        durability=ros.qos.DurabilityPolicy.TRANSIENT_LOCAL,
    )
    node.create_subscription(JointState, '/trainer_robot/joint_states',
                             lambda m: joints.append(np.array(m.position, float)), 100)
    node.create_subscription(Prompt, '/trainer/prompt',
                             lambda m: prompts.append((m, len(joints))), tl)
    node.create_subscription(Float64, '/trainer/ee_distance', lambda m: distances.append(m.data),
                             10)  # fmt: skip
    sim = spawn_node('mindgrasp_sim.sim_node', trainer_robot=True, camera_rate=1.0, duration=300.0)
    # left, right and an approach long enough to take the end-effector below 0.1 m. The trainer
    # runs on wall time and a simulator on a loaded machine realises only part of each move (its
    # real-time factor, down to ~0.3 under heavy load), so the moves are long: joint 2 must turn
    # about 1 rad and is commanded 0.45 rad/s for 12 s (5.4 rad; the reset ends it early), the
    # turns 0.1 rad/s for 12 s (1.2 rad)
    trainer = spawn_node('mindgrasp_trainer.trainer_node', n_trials=3, classes='[0, 1, 2]', seed=0,
                    balanced=True, approach_speed=0.45, turn_speed=0.1, move_duration=12.0,
                    wait_duration=0.5, start_delay=0.5, settle_time=3.0,
                    robot_timeout=60.0)  # fmt: skip
    ok = spin_until(node, lambda: prompts and prompts[-1][0].phase == 'end', 240.0)
    out = trainer.output()
    assert ok, f'prompts: {[(m.trial, m.phase) for m, _ in prompts]}\n{out}'
    assert trainer.wait(60) == 0
    out = trainer.output()
    assert sim.poll() is None, 'the simulator died'
    # Joint states and prompts are two topics from two processes: their order of arrival is not
    # their order in time. Only poses the robot holds for a whole phase are compared: the last
    # joint state before a phase's *next* prompt arrived (the robot stands still in 'wait', and
    # before a move starts), so a lag shorter than a phase does not matter.
    moves = [(m, q) for m, q in prompts if m.phase == 'move']
    assert sorted(m.class_index for m, _ in moves) == [0, 1, 2]
    for i, (a, n_a) in enumerate(prompts[:-2]):
        if a.phase != 'move':
            continue
        b, n_c = prompts[i + 1][0], prompts[i + 2][1]
        qa, qc = joints[n_a - 1], joints[n_c - 1]
        if a.class_index in (0, 1):  # joint 1 turns at 0.1 rad/s for 12 s, left +, right -
            assert b.phase == 'wait'
            sign = 1 if a.class_index == 0 else -1
            # at most 1.2 rad; less when the loaded machine keeps the simulator below real time
            assert 0.1 < sign * (qc - qa)[0] < 1.3, f'dq {qc - qa}'
            assert abs((qc - qa)[1]) < 0.02
        else:  # approach: joint 2 forward until the end-effector went below 0.1 m
            assert b.phase == 'rest', f'no 0.1 m reset, min distance {min(distances)}'
            assert 'Resetting both robots: training end-effector at 0.0' in out
    # the reset brought the training robot home: before the prompt after the rest (settle_time,
    # 3 s, after the reset) its joints are at the simulator's home pose again
    from mindgrasp_sim.simulation import HOME_POSE

    i_rest = next(i for i, (m, _) in enumerate(prompts) if m.phase == 'rest' and m.trial > 0)
    np.testing.assert_allclose(joints[prompts[i_rest + 1][1] - 1], HOME_POSE, atol=0.05)

    # distance: 0 at home (the robots coincide: during the 3 s settle after the reset, long after
    # this observer matched the trainer's publisher), growing as the training robot moves
    assert distances and min(distances) < 0.01 and max(distances) > 0.1
