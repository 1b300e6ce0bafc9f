"""Nodes on simulated time in a LockstepRunner: the virtual amplifier's ``output:=ros`` publishes
/eeg/raw stamped on sim time; the trial manager says what it waits for and gives up clearly; a
raising callback is reported with its node's name."""

from __future__ import annotations

import pytest

from mindgrasp_ros import rclpy
from mindgrasp_ros.graph import LockstepRunner, NodeCallbackError


class Listener(rclpy.node.Node):
    def __init__(self, msg_type: type, topic: str, qos: object = 10, **kwargs: object) -> None:
        super().__init__('listener', **kwargs)
        self.got: list = []
        self.create_subscription(msg_type, topic, self.got.append, qos)


def test_virtual_amp_publishes_eeg_on_sim_time() -> None:
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk

    from mindgrasp_eeg.virtual_amp_node import VirtualAmpNode

    with LockstepRunner(start_time_s=5.0) as runner:
        listener = runner.add(Listener, EEGChunk, '/eeg/raw', rclpy.qos.qos_profile_sensor_data)
        runner.add(VirtualAmpNode, ros_args=['-p', 'output:=ros', '-p', 'seed:=3'])
        for _ in range(100):
            runner.step(0.01)                               # 1 s of simulated time
    chunks = listener.got
    n = sum(int(c.n_samples) for c in chunks)
    assert 245 <= n <= 251                                  # 250 Hz for 1 s
    first = [int(c.first_sample_index) for c in chunks]
    assert first == [sum(int(c.n_samples) for c in chunks[:k]) for k in range(len(chunks))]
    stamps = [c.header.stamp.sec + 1e-9 * c.header.stamp.nanosec for c in chunks]
    # sample k of the stream is at (its first stamp) + k / 250 s, on the simulated clock
    for c, t in zip(chunks, stamps, strict=True):
        assert t == pytest.approx(stamps[0] + int(c.first_sample_index) / 250.0, abs=1e-6)
    assert 5.0 <= stamps[0] < 5.02 and chunks[0].unit == 'V' and len(chunks[0].channel_names) == 32


def test_virtual_amp_rejects_an_unknown_output() -> None:
    from mindgrasp_eeg.virtual_amp_node import VirtualAmpNode
    from mindgrasp_ros.params import ParameterError

    with LockstepRunner() as runner, \
            pytest.raises(ParameterError, match="'output' is 'udp'; use one of lsl, ros"):
        runner.add(VirtualAmpNode, ros_args=['-p', 'output:=udp'])


def test_trial_manager_waits_for_the_eeg_says_so_and_gives_up(caplog) -> None:
    from mindgrasp_experiments.trial_manager_node import TrialManagerNode
    from mindgrasp_sim.sim_node import SimNode

    with LockstepRunner(start_time_s=1.0) as runner:
        runner.add(SimNode, ros_args=['-p', 'camera_rate:=1.0'])
        manager = runner.add(TrialManagerNode, ros_args=[
            '-p', 'n_trials:=1', '-p', "wait_for:=['/eeg/raw']", '-p', 'ready_timeout:=2.0'])
        for _ in range(400):
            if manager.done.done():
                break
            runner.step(0.02)
    assert manager.done.done() and not manager.records
    assert manager.error.startswith('Gave up before trial 1: no messages on /eeg/raw after 2 s')
    # its parameters are read one way, as every node's: the declared dataclass
    assert manager.params.ready_timeout == 2.0 and not hasattr(manager, 'p')


def test_a_raising_callback_names_its_node() -> None:
    class Faulty(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('faulty', **kwargs)
            self.create_timer(0.1, self.boom)

        def boom(self) -> None:
            raise ZeroDivisionError('no luck')

    with LockstepRunner() as runner:
        runner.add(Faulty)
        with pytest.raises(NodeCallbackError, match="node 'faulty' raised ZeroDivisionError: "
                                                    'no luck'):
            for _ in range(20):
                runner.step(0.02)
