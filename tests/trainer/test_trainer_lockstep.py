"""Both nodes composed in lock-step on sim time (mindgrasp_ros.graph): prompt stamps fall on
the planned onsets, and a second run with the same seed publishes the same prompts."""

from __future__ import annotations

import numpy as np
import pytest

from mindgrasp_trainer.graz import GrazProtocol

FAST = {'n_trials': 8, 'seed': 4, 'start_delay': 0.5, 'fixation': 0.4, 'cue': 0.3,
        'imagery': 0.5, 'rest_min': 0.2, 'rest_max': 0.4}  # fmt: skip
STEP = 0.005  # s, the prompt timer's period at rate 200 Hz


@pytest.fixture
def runner():
    from mindgrasp_ros import graph

    return graph.LockstepRunner(start_time_s=100.0)


def run_graz(runner) -> list:
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    from mindgrasp_ros import rclpy
    from mindgrasp_trainer.graz_node import GrazNode

    got = []

    class Listener(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('prompt_listener', **kwargs)
            qos = rclpy.qos.QoSProfile(
                depth=10,
                reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL,
            )
            self.create_subscription(Prompt, '/trainer/prompt', got.append, qos)

    runner.add(Listener)
    args = [a for k, v in FAST.items() for a in ('-p', f'{k}:={v}')]
    node = runner.add(GrazNode, ros_args=[*args, '-p', 'display_rate:=0.0'])
    for _ in range(int(60 / STEP)):
        if node.finished:
            break
        runner.step(STEP)
    assert node.finished
    return got


def test_graz_in_lockstep_hits_the_planned_onsets(runner):
    got = run_graz(runner)
    expected = GrazProtocol(**FAST).schedule()
    assert [(m.phase, m.class_index, m.trial) for m in got] == [
        (e.phase, e.class_index, e.trial) for e in expected
    ]
    stamps = np.array([m.header.stamp.sec + m.header.stamp.nanosec * 1e-9 for m in got])
    onsets = np.array([e.onset for e in expected])
    # sim time: each phase starts on the first timer tick at or after its planned onset
    lag = (stamps - stamps[0]) - (onsets - onsets[0])
    assert (lag > -1e-6).all() and (lag < STEP + 1e-6).all()


def test_same_seed_same_prompts_in_lockstep():
    from mindgrasp_ros import graph

    runs = []
    for _ in range(2):
        runner = graph.LockstepRunner(start_time_s=100.0)
        runs.append([(m.phase, m.class_index, m.trial, m.header.stamp.sec,
                      m.header.stamp.nanosec) for m in run_graz(runner)])  # fmt: skip
    assert runs[0] == runs[1]


def run_trainer_with_sim() -> tuple[list, dict]:
    """Simulator (training robot) and trainer composed in lock-step; returns prompts, summary."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    from mindgrasp_ros import graph, rclpy
    from mindgrasp_sim import sim_node
    from mindgrasp_trainer.trainer_node import TrainerNode

    got = []

    class Listener(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('prompt_listener', **kwargs)
            qos = rclpy.qos.QoSProfile(
                depth=10,
                reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL,
            )
            self.create_subscription(Prompt, '/trainer/prompt', got.append, qos)

    runner = graph.LockstepRunner(start_time_s=100.0)
    runner.add(Listener)
    runner.add(sim_node.SimNode, ros_args=['-p', 'trainer_robot:=true', '-p', 'camera_rate:=1.0'])
    trainer = runner.add(TrainerNode, ros_args=[
        '-p', 'n_trials:=3', '-p', 'classes:=[0, 2]', '-p', 'seed:=1', '-p', 'start_delay:=0.5',
        '-p', 'approach_speed:=0.6', '-p', 'settle_time:=0.5',
    ])  # fmt: skip
    for _ in range(3000):
        if trainer.finished:
            break
        runner.step(0.01)
    assert trainer.finished and trainer.exit_code == 0
    prompts = [(m.phase, m.trial, m.class_index, m.header.stamp.sec, m.header.stamp.nanosec)
               for m in got]  # fmt: skip
    return prompts, trainer.protocol.summary()


@pytest.mark.slow
def test_trainer_and_simulator_in_lockstep_are_deterministic():
    a_prompts, a_summary = run_trainer_with_sim()
    # the approach (both hands, 0.6 rad/s) takes the training end-effector below 0.1 m: the
    # reset goes through the simulator's /sim/reset service in the same process
    assert a_summary['n_resets'] >= 1
    assert [p[0] for p in a_prompts].count('rest') == 1 + a_summary['n_resets']
    assert a_prompts[-1][0] == 'end'
    b_prompts, b_summary = run_trainer_with_sim()
    assert a_prompts == b_prompts
    assert a_summary == b_summary


def test_display_in_lockstep_draws_every_prompt_on_sim_time(tmp_path):
    """The headless participant display composed with the Graz prompter on simulated time: each
    prompt phase is drawn in the step it arrives (flip stamp = prompt stamp), with one PNG each,
    and PNGs at ``png_rate`` count simulated seconds."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    from mindgrasp_ros import graph, rclpy
    from mindgrasp_trainer.display_node import DisplayNode
    from mindgrasp_trainer.graz_node import GrazNode

    flips = []

    class Listener(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('flip_listener', **kwargs)
            self.create_subscription(Prompt, '/display/flip', flips.append, 50)

    png = tmp_path / 'png'
    runner = graph.LockstepRunner(start_time_s=100.0)
    runner.add(Listener)
    runner.add(DisplayNode, ros_args=['-p', 'headless:=true', '-p', f'png_dir:={png}',
                                      '-p', 'rate:=10.0', '-p', 'png_rate:=0.5',
                                      '-p', 'width:=400', '-p', 'height:=240'])
    args = [a for k, v in FAST.items() for a in ('-p', f'{k}:={v}')]
    graz = runner.add(GrazNode, ros_args=[*args, '-p', 'display_rate:=0.0'])
    while not graz.finished and runner.time_s < 160.0:
        runner.step(STEP)
    for _ in range(round(10.0 / STEP)):  # 10 simulated s without prompts
        runner.step(STEP)
    runner.close()
    assert graz.finished
    expected = GrazProtocol(**FAST).schedule()
    assert [(f.trial, f.phase) for f in flips] == [(e.trial, e.phase) for e in expected]
    for f, e in zip(flips, expected, strict=True):  # drawn in the step the prompt came
        assert f.header.stamp.sec + 1e-9 * f.header.stamp.nanosec >= 100.0 + e.onset
    numbers = {int(p.stem.split('_')[1]): p.name for p in png.glob('*.png')}
    tagged = [n for n, name in numbers.items() if '_graz_' in name]
    assert len(tagged) == len(expected)                  # one PNG per drawn prompt phase
    # then png_rate 0.5 Hz of simulated time: a frame every 2 simulated s
    assert len([n for n in numbers if n > max(tagged)]) in (4, 5, 6)
