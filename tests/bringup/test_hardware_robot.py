"""robot:= on the hardware profile: the controller reads the description of the driver's arm. A
simulated xArm6 stands in as the arm driver (its own process, real DDS, ``/joint_states`` with
the xArm's joint names); with ``robot:=xarm6`` the controller takes those joint states (it then
waits for the EEG, which this test does not stream); with the shipped arm's description it would
wait for joint states it can use for ever."""

from __future__ import annotations

import os
import time

import pytest

from mindgrasp_ros.node_process import NodeProcess

pytestmark = pytest.mark.slow

MODEL = 'model:=package://mindgrasp_classifier/models/default_classifier.json'


@pytest.mark.timeout(600)
def test_the_controller_reads_the_drivers_arm(rclpy_ctx, tmp_path) -> None:
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState

    from mindgrasp_ros.topics import FSM_STATE

    run_dir = tmp_path / 'run'
    launch = NodeProcess('mindgrasp_cli', [
        'launch', 'hardware', 'eeg_stream:=NoAmp', 'eeg_source_id:=amp-1', 'eeg_host:=local',
        'arm_driver:=mindgrasp_sim.sim_node',
        'arm_driver_args:=--ros-args -p robot:=xarm6', MODEL, 'robot:=xarm6', 'record:=false',
        'require_ready_model:=false',
        '--run-dir', str(run_dir)], dict(os.environ), tmp_path / 'launch.log')
    node = rclpy_ctx.create_node('hardware_probe')
    reasons: list[str] = []
    node.create_subscription(FsmState, FSM_STATE.name, lambda m: reasons.append(m.reason),
                             FSM_STATE.qos)
    waiting_for_eeg = 'stopped: no MI prediction received yet'
    try:
        assert _spin(rclpy_ctx, node, reasons, waiting_for_eeg), launch.output()
    finally:
        code = launch.stop(timeout=30)
        node.destroy_node()
    assert code == 130, launch.output()         # stopped by SIGINT: an interrupted run
    assert "with the robot 'xarm6'" in (run_dir / 'logs' / 'arm_driver.log').read_text()


def _spin(rclpy, node, reasons: list[str], wanted: str, timeout: float = 120.0) -> bool:
    """Spin ``node`` until ``wanted`` is among ``reasons`` (True) or ``timeout`` s pass."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and wanted not in reasons:
        rclpy.spin_once(node, timeout_sec=0.1)
    return wanted in reasons
