"""Scripted, physical motions of the simulated arm (ROS-free): joint moves under velocity control,
straight-line Cartesian moves through inverse kinematics, and a top-down grasp-and-lift.

Everything goes through :meth:`Simulation.set_joint_velocities` / :meth:`Simulation.set_gripper`
and physics steps, as a controller would drive it; nothing is teleported or welded.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mindgrasp_common.geometry import top_down_quat
from mindgrasp_common.types import SceneObject
from mindgrasp_sim.simulation import Simulation

#: object centre height above which a held object counts as lifted (m), as in the original code
SUCCESS_HEIGHT = 0.22


@dataclass
class GraspOutcome:
    """Result of :func:`grasp_object_at`: ``success`` when the object ended above ``lift_height``
    in the gripper; ``lift_height`` is the object's centre height (m) at the end; ``held`` the
    object held at the end (or None); ``time`` the simulated seconds used."""

    success: bool
    lift_height: float
    held: SceneObject | None
    time: float
    reason: str = ''


def move_joints(sim: Simulation, q_target: np.ndarray, robot: str = 'user', gain: float = 3.0,
                tolerance: float = 0.005, timeout: float = 6.0,
                max_speed: float | None = None) -> bool:
    """Drive the arm to joint positions ``q_target`` (n_joints,) rad with proportional velocity
    commands (rad/s, within the joint limits). Returns True when within ``tolerance`` rad."""
    q_target = np.clip(np.asarray(q_target, dtype=float), sim.lower, sim.upper)
    vmax = sim.max_velocity if max_speed is None else np.minimum(sim.max_velocity, max_speed)
    steps = int(timeout * sim.physics_hz)
    for i in range(steps):
        err = q_target - sim.joint_positions(robot)
        if np.max(np.abs(err)) < tolerance:
            break
        if i % 4 == 0:   # a 60 Hz controller, as a driver would run it
            sim.set_joint_velocities(np.clip(gain * err, -vmax, vmax), robot=robot)
        sim.step()
    sim.stop(robot)
    sim.step(2)
    return bool(np.max(np.abs(q_target - sim.joint_positions(robot))) < 2 * tolerance)


def move_tcp_line(sim: Simulation, target: np.ndarray, quat: np.ndarray, robot: str = 'user',
                  speed: float = 0.15, tolerance: float = 0.004) -> bool:
    """Move the TCP in a straight line to ``target`` (3,) m keeping orientation ``quat`` (xyzw),
    at about ``speed`` m/s, through IK waypoints every 1 cm. Returns True when it arrives."""
    start, _ = sim.ee_pose(robot)
    target = np.asarray(target, dtype=float)
    n = max(1, math.ceil(np.linalg.norm(target - start) / 0.01))
    q = sim.joint_positions(robot)
    for k in range(1, n + 1):
        waypoint = start + (target - start) * k / n
        q_next = sim.inverse_kinematics(waypoint, quat, robot=robot, seed_q=q)
        dq = q_next - sim.joint_positions(robot)
        # time for this 1 cm segment at the requested speed, stretched by the joint limits
        seg = np.linalg.norm(target - start) / n
        t = max(seg / speed, float(np.max(np.abs(dq) / sim.max_velocity)))
        steps = max(1, round(t * sim.physics_hz))
        sim.set_joint_velocities(dq / (steps / sim.physics_hz), robot=robot)
        sim.step(steps)
        q = q_next
    ok = move_joints(sim, q, robot=robot, tolerance=0.002, timeout=2.0)
    pos, _ = sim.ee_pose(robot)
    return ok and float(np.linalg.norm(pos - target)) < tolerance * 3


def grasp_yaw(obj: SceneObject) -> float:
    """Gripper yaw (rad) for a top-down grasp: thumb towards the base; for cubes snapped to the
    nearest face normal so that the fingers close on two parallel faces."""
    bearing = math.atan2(obj.position[1], obj.position[0])
    if obj.shape != 'cube':
        return bearing
    obj_yaw = 2 * math.atan2(obj.orientation[2], obj.orientation[3])
    k = round((bearing - obj_yaw) / (math.pi / 2))
    return obj_yaw + k * math.pi / 2


def grasp_object_at(sim: Simulation, obj: SceneObject | int, robot: str = 'user',
                    lift_to: float = 0.35, approach_height: float = 0.15) -> GraspOutcome:
    """Grasp ``obj`` from above and lift it to ``lift_to`` m (TCP height).

    Pre-grasp above the object, straight descent until the fingertips are just above the
    ground, force-limited closing, 1 s settle, straight lift. Success: the object is held by
    >= 2 fingers, off the ground, with its centre above :data:`SUCCESS_HEIGHT`.
    """
    t0 = sim.time
    if isinstance(obj, int):
        obj = sim.objects()[obj]
    centre = obj.position.copy()
    quat = top_down_quat(grasp_yaw(obj))
    # fingertips reach 0.022 m beyond the TCP when open: keep them 6 mm above the ground
    grasp_z = max(centre[2], 0.028)
    above = np.array([centre[0], centre[1], grasp_z + approach_height])
    sim.set_gripper(0.0, robot=robot)
    q_pre = sim.inverse_kinematics(above, quat, robot=robot)
    if not move_joints(sim, q_pre, robot=robot, timeout=8.0):
        return GraspOutcome(False, 0.0, None, sim.time - t0, 'could not reach the pre-grasp')
    if not move_tcp_line(sim, np.array([centre[0], centre[1], grasp_z]), quat, robot=robot,
                         speed=0.1):
        return GraspOutcome(False, 0.0, None, sim.time - t0, 'could not reach the grasp pose')
    sim.set_gripper(1.0, robot=robot)
    sim.step(int(1.2 * sim.physics_hz))
    move_tcp_line(sim, np.array([centre[0], centre[1], lift_to]), quat, robot=robot, speed=0.1)
    sim.step(int(0.5 * sim.physics_hz))
    held = sim.held_object(robot)
    now = sim.objects()[obj.object_id]
    height = float(now.position[2])
    ok = held is not None and held.object_id == obj.object_id and height > SUCCESS_HEIGHT
    reason = 'lifted' if ok else ('not held' if held is None else f'held {held.label}')
    return GraspOutcome(ok, height, held, sim.time - t0, reason)


__all__ = ['SUCCESS_HEIGHT', 'GraspOutcome', 'grasp_object_at', 'grasp_yaw', 'move_joints',
           'move_tcp_line']
