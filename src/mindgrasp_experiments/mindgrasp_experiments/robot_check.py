"""Checks of a robot description before an experiment (``mindgrasp robot check FILE.yaml``).

Each check gives :class:`Finding` lines: ``ok`` or a fault that names what to fix, in one line.
In order, each only when the ones before it passed:

1. the description loads (:func:`~mindgrasp_common.robot_description.load_robot`: joints, limits,
   links, the URDFs, the mount): its one-line error otherwise;
2. the joint table (arm joints with limits and home, hand joints with open and closed);
3. the TCP (:func:`tcp_findings`): outside every link of the robot with the hand open (a TCP
   inside the palm or a finger is a fault), and the fingertips closer to it closed than open
   (else ``open`` and ``closed`` are swapped);
4. the camera (:func:`camera_findings`): at home its optical axis meets the table in front of
   the arm within the scene's reach and the image shows part of the workspace (a camera looking
   up, back or sideways is a fault); the hand does not fill the image; the first image is
   saved (``camera.png``: colour and depth);
5. the reachability map (:func:`reachability`): for object positions over the random-locations
   scene, whether the controller's grasp planner finds a pre-grasp and a grasp pose
   (``reachability.png``, ``reachability.csv``);
6. (the command) a few autonomous random-locations grasps in lock-step, counted per shape.

ROS-free; the simulation and the controller's kinematics are the ones experiments use.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_common.robot_description import RobotDescription

__all__ = ['Finding', 'camera_findings', 'joint_table', 'reachability', 'tcp_findings']

#: the random-locations scene's annulus (m) and angles (rad) objects are drawn from
REACH = (0.2, 0.7)
ANGLES = (-math.radians(170.0), math.radians(170.0))


@dataclass(frozen=True)
class Finding:
    """One check: ``ok`` and the line that says what was found (and, if not ok, the fix)."""

    ok: bool
    line: str


def joint_table(robot: RobotDescription) -> list[str]:
    """The joints as text lines: arm joints with limits (rad), velocity (rad/s), effort and
    home; hand joints with limits and the open/closed positions of the closure synergy."""
    lines = [f"{'joint':<28} {'part':<5} {'lower':>8} {'upper':>8} {'vel':>6} {'effort':>7}  "
             'home / open..closed']
    for j, lim, q, v in zip(robot.arm_joints, robot.arm_limits, robot.home_pose,
                            robot.max_velocity, strict=True):
        lines.append(f'{j:<28} {"arm":<5} {lim.lower:>8.3f} {lim.upper:>8.3f} {v:>6.2f} '
                     f'{lim.effort:>7.1f}  {q:.3f}')
    g = robot.gripper
    mimic = {m[0]: m[1] for m in g.mimic}
    for j, lim, a, b in zip(g.joints, g.limits, g.open, g.closed, strict=True):
        note = f' (mimics {mimic[j]})' if j in mimic else ''
        lines.append(f'{j:<28} {"hand":<5} {lim.lower:>8.3f} {lim.upper:>8.3f} '
                     f'{lim.velocity:>6.2f} {lim.effort:>7.1f}  {a:.3f}..{b:.3f}{note}')
    return lines


def _hand_links(sim) -> dict[int, str]:
    """PyBullet link index -> name of the links of the hand (the hand root and below)."""
    p, body = sim.client, sim.body()
    names = {j: p.getJointInfo(body, j)[12].decode() for j in range(p.getNumJoints(body))}
    parent = {j: p.getJointInfo(body, j)[16] for j in names}
    root = next((j for j, n in names.items() if n == sim.robot.hand_root), None)
    out = {}
    for j in names:
        k = j
        while k != -1 and k != root:
            k = parent[k]
        if k == root and root is not None:
            out[j] = names[j]
    return out


def tcp_findings(sim) -> list[Finding]:
    """The TCP of ``sim``'s robot (a :class:`~mindgrasp_sim.simulation.Simulation` at home,
    hand open): not inside any link, and approached by the fingertips as the hand closes."""
    from mindgrasp_sim.pybullet_quiet import pb

    p, body = sim.client, sim.body()
    tcp, _ = sim.ee_pose()
    probe = p.createMultiBody(0, p.createCollisionShape(pb.GEOM_SPHERE, radius=0.002), -1,
                              tcp.tolist())
    names = {j: p.getJointInfo(body, j)[12].decode() for j in range(p.getNumJoints(body))}
    names[-1] = 'base'
    inside = sorted({(c[8], names[c[4]]) for c in p.getClosestPoints(probe, body, 0.0)
                     if c[8] < -0.002})
    out = []
    if inside:
        depth, link = inside[0]
        out.append(Finding(False, f'the TCP is inside the link {link!r} ({-depth * 1000:.0f} mm '
                                  f'deep with the hand open); move tcp: xyz out of the palm to '
                                  'the grasp point between the fingertips'))
    else:
        out.append(Finding(True, f'the TCP is clear of every link with the hand open '
                                 f'({tcp[0]:.3f}, {tcp[1]:.3f}, {tcp[2]:.3f}) m at home'))

    def spread() -> float:
        # mean distance of the moving finger links' closest points to the TCP
        moving = set(sim.finger_joint_indices)
        d = [min((c[8] for c in p.getClosestPoints(probe, body, 0.5, linkIndexB=j)),
                 default=math.nan) for j in moving]
        return float(np.nanmean(d)) if d else math.nan

    open_spread = spread()
    g = sim.robot.gripper
    for j, q in zip(sim.finger_joint_indices, g.closed, strict=True):
        p.resetJointState(body, j, q)
    p.performCollisionDetection()
    closed_spread = spread()
    for j, q in zip(sim.finger_joint_indices, g.open, strict=True):
        p.resetJointState(body, j, q)
    p.performCollisionDetection()
    if math.isfinite(open_spread) and math.isfinite(closed_spread) \
            and closed_spread > open_spread + 1e-3:
        out.append(Finding(False, f'closing the hand moves its fingers away from the TCP '
                                  f'({open_spread * 1000:.0f} -> {closed_spread * 1000:.0f} mm); '
                                  'swap the hand\'s open: and closed: positions'))
    else:
        out.append(Finding(True, f'closing the hand brings its fingers to the TCP '
                                 f'({open_spread * 1000:.0f} -> {closed_spread * 1000:.0f} mm)'))
    p.removeBody(probe)
    return out


def camera_findings(sim, out_dir: Path | None = None) -> list[Finding]:
    """The eye-in-hand camera at home: looks at the workspace (its optical axis meets the table
    0.1-1.2 m from the base, and some of the scene's annulus is in the image), is not covered
    by the hand; the first image saved as ``out_dir/camera.png``."""
    pos, quat = sim.camera_pose()
    rot = Rotation.from_quat(quat).as_matrix()
    axis = rot[:, 2]
    k, w, h = sim.camera_intrinsics()
    # the scene's annulus in front of and around the arm, on the table
    r = np.linspace(*REACH, 11)
    a = np.linspace(*ANGLES, 69)
    rr, aa = np.meshgrid(r, a)
    pts = np.stack([rr * np.cos(aa), rr * np.sin(aa), np.full_like(rr, 0.02)], -1).reshape(-1, 3)
    cam = (pts - pos) @ rot                       # in the optical frame
    front = cam[:, 2] > 0.05
    u = k[0, 0] * cam[:, 0] / np.where(front, cam[:, 2], 1) + k[0, 2]
    v = k[1, 1] * cam[:, 1] / np.where(front, cam[:, 2], 1) + k[1, 2]
    seen = front & (u >= 0) & (u < w) & (v >= 0) & (v < h)
    rgb, depth = sim.render_camera(exact=True)
    out = []
    where = (f'at ({pos[0]:.2f}, {pos[1]:.2f}, {pos[2]:.2f}) m looking along '
             f'({axis[0]:.2f}, {axis[1]:.2f}, {axis[2]:.2f})')
    hit = None
    if axis[2] < -1e-3:
        t = -pos[2] / axis[2]
        hit = pos + t * axis
    reach = math.hypot(*hit[:2]) if hit is not None else math.inf
    if hit is None or not 0.1 <= reach <= 1.2 or not seen.any():
        way = ('up or level, never at the table' if hit is None else
               f'at the table {reach:.2f} m from the base' if seen.any() else
               'away from the workspace (no point of the 0.2-0.7 m annulus in its image)')
        out.append(Finding(False, f'the camera looks away from the objects: {where}, '
                                  f'{way}; turn camera: rpy so its z axis (optical axis) points '
                                  'along the tool, down at the table'))
    else:
        out.append(Finding(True, f'the camera {where} sees the table {reach:.2f} m from the base '
                                 f'and {seen.mean() * 100:.0f} % of the workspace'))
    near = float(np.mean(np.nan_to_num(depth, nan=10.0) < 0.08))
    if near > 0.5:
        out.append(Finding(False, f'the hand covers {near * 100:.0f} % of the camera image (nearer '
                                  'than 8 cm); move the camera mount (camera: xyz) beside the '
                                  'fingers'))
    if out_dir is not None:
        from PIL import Image

        d = np.nan_to_num(depth, nan=0.0)
        grey = (255 * (1 - np.clip(d / max(float(d.max()), 1e-6), 0, 1))).astype(np.uint8)
        Image.fromarray(np.hstack([rgb, np.repeat(grey[:, :, None], 3, axis=2)])).save(
            out_dir / 'camera.png')
    return out


def reachability(robot: RobotDescription, out_dir: Path | None = None,
                 shape: str = 'cube') -> tuple[float, np.ndarray]:
    """Object positions over the random-locations scene (0.2-0.7 m, -170..170 deg) where the
    controller's planner (:meth:`~mindgrasp_fsm.grasp_policy.GraspPolicy.reachable`) finds a
    pre-grasp and a grasp pose of ``shape``. Returns the reachable fraction and rows
    (x m, y m, reachable 0/1); writes ``reachability.csv`` and ``.png`` to ``out_dir``."""
    from mindgrasp_fsm.grasp_fsm import GraspFsm
    from mindgrasp_fsm.params import FsmParams

    fsm = GraspFsm.from_params(FsmParams(robot=robot.spec))
    q = np.array(robot.home_pose)
    rows = []
    for r in np.arange(REACH[0], REACH[1] + 1e-9, 0.05):
        for a in np.radians(np.arange(-170, 171, 20)):
            x, y = r * math.cos(a), r * math.sin(a)
            ok = fsm.policy.reachable(np.array([x, y, 0.025]), shape, q) == ''
            rows.append((x, y, float(ok)))
    table = np.array(rows)
    if out_dir is not None:
        np.savetxt(out_dir / 'reachability.csv', table, delimiter=',', fmt='%.3f',
                   header='x_m,y_m,reachable', comments='')
        import matplotlib
        matplotlib.use('Agg')
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(4.5, 4.5))
        ok = table[:, 2] > 0
        ax.scatter(table[ok, 0], table[ok, 1], s=12, c='tab:green', label='grasp pose')
        ax.scatter(table[~ok, 0], table[~ok, 1], s=12, c='tab:red', marker='x', label='none')
        ax.scatter([0], [0], s=60, c='k', marker='s', label='arm base')
        ax.set_aspect('equal')
        ax.set_xlabel('x (m)')
        ax.set_ylabel('y (m)')
        ax.set_title(f'{robot.name}: {shape} grasp poses ({ok.mean() * 100:.0f} %)')
        ax.legend(loc='lower left', fontsize=7)
        fig.tight_layout()
        fig.savefig(out_dir / 'reachability.png', dpi=100)
        plt.close(fig)
    return float(table[:, 2].mean()), table
