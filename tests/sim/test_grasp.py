"""Physical grasps: each shape (4-6 cm) is picked from above by friction alone and lifted above
0.22 m; the task monitor reports lifts and drops."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_sim.scripted import SUCCESS_HEIGHT, grasp_object_at, move_tcp_line
from mindgrasp_sim.simulation import Simulation, top_down_quat
from mindgrasp_sim.task import TaskMonitor

pytestmark = pytest.mark.slow


def one_object_scene(shape: str, size: float, xy: tuple[float, float], yaw_deg: float = 0.0):
    return {'name': 'one', 'objects': [{'shape': shape, 'colour': 'red', 'size': size,
                                        'position': list(xy), 'yaw_deg': yaw_deg}]}


@pytest.mark.parametrize('shape', ['cube', 'cylinder', 'sphere'])
@pytest.mark.parametrize('size', [0.04, 0.06])
def test_scripted_grasp_lifts_each_shape(shape, size):
    with Simulation(one_object_scene(shape, size, (0.45, 0.12), yaw_deg=20.0)) as sim:
        obj = sim.objects()[0]
        out = grasp_object_at(sim, obj)
        assert out.success, out.reason
        assert out.lift_height > SUCCESS_HEIGHT
        held = sim.held_object()
        assert held is not None and held.object_id == obj.object_id
        # held by friction: at least two fingers touch it, and it moves with the hand
        assert sim.gripper_state()['contacts'].sum() >= 2
        tcp_before, obj_before = sim.ee_pose()[0], sim.objects()[0].position
        sim.set_joint_velocities(np.array([0.4, 0, 0, 0, 0, 0]))
        sim.step(120)
        sim.stop()
        sim.step(60)
        moved = sim.objects()[0].position - obj_before
        np.testing.assert_allclose(moved, sim.ee_pose()[0] - tcp_before, atol=0.01)
        assert np.linalg.norm(moved) > 0.05


def test_no_welding_an_open_gripper_drops_the_object():
    with Simulation(one_object_scene('cube', 0.05, (0.5, 0.0))) as sim:
        assert grasp_object_at(sim, 0).success
        sim.set_gripper(0.0)
        sim.step(int(1.5 * sim.physics_hz))
        assert sim.held_object() is None
        assert sim.objects()[0].position[2] < 0.1


def test_task_monitor_reports_success_and_drop():
    with Simulation(one_object_scene('cylinder', 0.05, (0.4, -0.2))) as sim:
        monitor = TaskMonitor()
        monitor.new_trial(sim.time)
        events = []
        obj = sim.objects()[0]
        quat = top_down_quat(math.atan2(obj.position[1], obj.position[0]))
        grasp = np.array([obj.position[0], obj.position[1], 0.028])
        sim.set_joint_positions(sim.inverse_kinematics(grasp + np.array([0, 0, 0.1]), quat))
        move_tcp_line(sim, grasp, quat)
        sim.set_gripper(1.0)
        for _ in range(int(1.2 * sim.physics_hz) // 8):
            sim.step(8)
            events.append(monitor.update(sim))
        # lift to 0.15 m (below the success height), then open: a drop
        move_tcp_line(sim, grasp + np.array([0, 0, 0.15]), quat)
        assert monitor.update(sim) is None
        sim.set_gripper(0.0)
        for _ in range(60):
            sim.step(4)
            events.append(monitor.update(sim))
        events = [e for e in events if e is not None]
        assert len(events) == 1
        assert not events[0].success and events[0].reason == 'dropped'
        assert events[0].grasped_object == 'red cylinder' and events[0].trial == 1
        assert 0.1 < events[0].lift_height < SUCCESS_HEIGHT

        sim.reset()
        monitor.new_trial(sim.time)
        out = grasp_object_at(sim, 0)
        assert out.success
        event = monitor.update(sim)
        assert event is not None and event.success and event.trial == 2
        assert event.lift_height > SUCCESS_HEIGHT
        assert monitor.update(sim) is None    # reported once


def test_random_locations_are_graspable():
    results = []
    with Simulation('random_locations', seed=0) as sim:
        for seed in (11, 12):
            sim.reset(seed=seed)
            for obj in sim.objects():
                sim.reset()
                out = grasp_object_at(sim, obj)
                results.append((obj.shape, round(math.hypot(*obj.position[:2]), 2), out.reason))
    failures = [r for r in results if r[2] != 'lifted']
    assert not failures, failures
