"""Behaviour of the ROS-free Simulation: kinematics, velocity control, limits, camera, reset,
determinism, trainer robot, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_helpers import colour_mask

from mindgrasp_common.resources import resource_path
from mindgrasp_sim.camera import CameraConfig
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.robot_model import ArmSpec, build_urdf
from mindgrasp_sim.simulation import Simulation, top_down_quat


def _rot(axis: str, a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    if axis == 'z':
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])   # about y


def fk_tcp(q: np.ndarray, spec: ArmSpec | None = None) -> np.ndarray:
    """Independent forward kinematics of the TCP (m) from the arm's dimensions."""
    spec = spec or ArmSpec()
    offsets = [spec.base_height, spec.turret_height, spec.long_arm, spec.link3, spec.short_arm,
               spec.wrist, spec.palm + spec.tcp_offset]
    axes = ['z', 'y', 'y', 'y', 'y', 'z']
    pos, rot = np.zeros(3), np.eye(3)
    for i in range(6):
        pos = pos + rot @ np.array([0, 0, offsets[i]])
        rot = rot @ _rot(axes[i], q[i])
    return pos + rot @ np.array([0, 0, offsets[6]])


def test_committed_urdf_is_the_generated_one():
    committed = resource_path('mindgrasp_sim', 'urdf', 'mindgrasp_arm.urdf').read_text()
    assert committed == build_urdf(), 'regenerate with python -m mindgrasp_sim.robot_model'


def test_api_shapes(sim):
    assert sim.joint_names == ('joint_1', 'joint_2', 'joint_3', 'joint_4', 'joint_5', 'joint_6')
    assert sim.joint_positions().shape == (6,)
    assert sim.joint_velocities().shape == (6,)
    np.testing.assert_allclose(sim.joint_positions(), sim.home_pose, atol=1e-9)
    pos, quat = sim.ee_pose()
    assert pos.shape == (3,) and quat.shape == (4,)
    k, w, h = sim.camera_intrinsics()
    assert k.shape == (3, 3) and (w, h) == (128, 128)
    state = sim.gripper_state()
    assert state['positions'].shape == (3,) and state['contacts'].shape == (3,)
    assert len(sim.objects()) == 9


@pytest.mark.parametrize('joint', range(6))
def test_joint_sweeps_move_the_tcp_as_kinematics_says(sim, joint):
    for angle in (-0.6, 0.3, 0.8):
        q = sim.home_pose.copy()
        q[joint] += angle
        q = np.clip(q, sim.lower, sim.upper)
        sim.set_joint_positions(q)
        sim.step(1)
        np.testing.assert_allclose(sim.ee_pose()[0], fk_tcp(sim.joint_positions()), atol=2e-4)
        np.testing.assert_allclose(sim.forward_kinematics(q)[0], fk_tcp(q), atol=1e-6)


def test_home_pose_reach_and_limits(sim):
    straight = np.array([0, math.pi / 2, 0, 0, 0, 0])
    reach = math.hypot(*fk_tcp(straight)[:2])
    assert 0.9 < reach < 1.0   # wrist at 0.78 m from the shoulder, TCP 0.14 m further
    assert np.all(sim.lower < sim.home_pose) and np.all(sim.home_pose < sim.upper)


def test_velocity_command_moves_joints_at_the_commanded_rate(sim):
    v = np.array([0.3, -0.2, 0.25, -0.3, 0.4, 0.5])
    q0 = sim.joint_positions()
    sim.set_joint_velocities(v)
    sim.step(int(0.2 * sim.physics_hz))   # let the motors catch up
    q1, t1 = sim.joint_positions(), sim.time
    sim.step(int(1.0 * sim.physics_hz))
    rate = (sim.joint_positions() - q1) / (sim.time - t1)
    np.testing.assert_allclose(rate, v, rtol=0.03, atol=0.005)
    np.testing.assert_allclose(sim.joint_velocities(), v, rtol=0.05, atol=0.01)
    assert np.all(np.abs(q1 - q0) > 0)


def test_velocity_is_clipped_to_the_joint_limit_rate(sim):
    sim.set_joint_velocities(np.array([10.0, 0, 0, 0, 0, 0]))
    sim.step(int(0.5 * sim.physics_hz))
    assert sim.commanded_velocities()[0] == pytest.approx(sim.max_velocity[0])
    assert sim.joint_velocities()[0] == pytest.approx(sim.max_velocity[0], rel=0.05)


def test_position_limits_stop_the_arm(sim):
    sim.set_joint_positions(np.array([2.8, 0, 0, 1.57, 1.2, -2.8]))
    sim.set_joint_velocities(np.array([1.0, 0, 0, 0, 0, -1.0]))
    sim.step(int(1.0 * sim.physics_hz))
    q = sim.joint_positions()
    assert q[0] == pytest.approx(sim.upper[0], abs=0.005)
    assert q[5] == pytest.approx(sim.lower[5], abs=0.005)
    assert abs(sim.joint_velocities()[0]) < 0.01


def test_zero_command_holds_still_against_gravity(sim):
    sim.step(int(0.5 * sim.physics_hz))
    q0 = sim.joint_positions()
    sim.step(int(3 * sim.physics_hz))
    np.testing.assert_allclose(sim.joint_positions(), q0, atol=2e-4)


def test_gripper_closes_and_opens(sim):
    open_q = sim.finger_positions()
    sim.set_gripper(1.0)
    sim.step(int(1.5 * sim.physics_hz))
    closed_q = sim.finger_positions()
    assert np.all(closed_q > open_q + 1.0)
    assert sim.gripper_state()['closure'] == 1.0
    sim.set_gripper(0.0)
    sim.step(int(1.5 * sim.physics_hz))
    np.testing.assert_allclose(sim.finger_positions(), open_q, atol=0.05)


def test_home_camera_sees_the_objects_in_front(sim):
    rgb, depth = sim.render_camera()
    assert rgb.shape == (128, 128, 3) and rgb.dtype == np.uint8
    assert depth.shape == (128, 128) and depth.dtype == np.float32
    # red cube straight ahead near the centre, blue cylinder (+40 deg, left), yellow sphere right
    for colour, cols in (('red', (44, 84)), ('blue', (0, 20)), ('yellow', (108, 128))):
        mask = colour_mask(rgb, colour)
        assert mask.sum() > 20, f'{colour} not seen'
        ys, xs = np.nonzero(mask)
        assert cols[0] <= xs.mean() <= cols[1], f'{colour} at column {xs.mean():.0f}'
        assert 40 <= ys.mean() <= 110


def _project(sim: Simulation, point: np.ndarray) -> tuple[float, float, float]:
    k, _, _ = sim.camera_intrinsics()
    pos, quat = sim.camera_pose()
    rot = np.array(__import__('pybullet').getMatrixFromQuaternion(quat)).reshape(3, 3)
    pc = rot.T @ (point - pos)
    uvw = k @ pc
    return uvw[0] / uvw[2], uvw[1] / uvw[2], pc[2]


def test_objects_appear_where_the_camera_model_projects_them(sim):
    q = sim.home_pose.copy()
    checked = 0
    for yaw in (0.0, math.radians(40), math.radians(-80), math.radians(160)):
        q[0] = yaw
        sim.set_joint_positions(q)
        rgb, _ = sim.render_camera()
        for obj in sim.objects():
            u, v, z = _project(sim, obj.position)
            if not (z > 0 and 8 <= u < 120 and 8 <= v < 120):
                continue
            mask = colour_mask(rgb, obj.colour)
            ys, xs = np.nonzero(mask)
            near = np.hypot(xs - u, ys - v) < 12
            assert near.sum() > 10, f'{obj.label} not at its projected pixel ({u:.0f}, {v:.0f})'
            # the blob of that colour around the projection is centred on it
            assert np.hypot(xs[near].mean() - u, ys[near].mean() - v) < 4
            checked += 1
    assert checked >= 4


def test_depth_is_metric(sim):
    # camera straight down above open ground: depth = camera height; and on top of the red cube
    q = sim.inverse_kinematics(np.array([0.45, -0.15, 0.40]), top_down_quat(0.0))
    sim.set_joint_positions(q)
    pos, _ = sim.camera_pose()
    _, depth = sim.render_camera()
    u, v, _ = _project(sim, np.array([pos[0], pos[1], 0.0]))
    assert depth[round(v), round(u)] == pytest.approx(pos[2], abs=0.01)
    cube = sim.objects()[0]
    top = cube.position + np.array([0, 0, cube.size / 2])
    q = sim.inverse_kinematics(top + np.array([0, 0, 0.25]), top_down_quat(0.0))
    sim.set_joint_positions(q)
    pos, _ = sim.camera_pose()
    _, depth = sim.render_camera()
    u, v, z = _project(sim, top)
    assert depth[round(v), round(u)] == pytest.approx(z, abs=0.01)
    assert z == pytest.approx(pos[2] - top[2], abs=0.02)


def test_reset_restores_the_scene(sim):
    before = [o.position.copy() for o in sim.objects()]
    sim.set_joint_velocities(np.array([0.5, 0.8, 0, 0, 0, 0]))
    sim.step(int(1.0 * sim.physics_hz))
    sim.set_gripper(1.0)
    sim.step(10)
    sim.reset()
    assert sim.time == 0.0
    np.testing.assert_allclose(sim.joint_positions(), sim.home_pose, atol=1e-9)
    np.testing.assert_array_equal(sim.commanded_velocities(), np.zeros(6))
    assert sim.gripper_state()['closure'] == 0.0
    for b, o in zip(before, sim.objects(), strict=True):
        np.testing.assert_allclose(o.position, b, atol=1e-9)


def test_set_locations_layout(sim):
    expected = [('red cube', 0), ('blue cylinder', 40), ('yellow sphere', -40),
                ('yellow cube', 80), ('red cylinder', 120), ('blue sphere', 160),
                ('blue cube', -80), ('red sphere', -120), ('yellow cylinder', -160)]
    for obj, (label, angle) in zip(sim.objects(), expected, strict=True):
        assert obj.label == label
        assert math.hypot(*obj.position[:2]) == pytest.approx(0.5)
        assert math.degrees(math.atan2(obj.position[1], obj.position[0])) == pytest.approx(angle)
        assert 0.04 <= obj.size <= 0.06 and 0.02 < obj.mass < 0.2
    # objects (spheres too) stay in place for a while
    sim.step(int(2 * sim.physics_hz))
    for obj, (_, angle) in zip(sim.objects(), expected, strict=True):
        a = math.radians(angle)
        np.testing.assert_allclose(obj.position[:2], [0.5 * math.cos(a), 0.5 * math.sin(a)],
                                   atol=0.002)


def test_random_draws_are_seeded_and_valid(random_sim):
    first = [o.position.copy() for o in random_sim.objects()]
    random_sim.reset(new_random_draw=True)
    second = [o.position.copy() for o in random_sim.objects()]
    assert not np.allclose(first[0], second[0])
    random_sim.reset(seed=3)
    np.testing.assert_allclose([o.position for o in random_sim.objects()], first)
    for seed in range(20):
        random_sim.reset(seed=seed)
        objs = random_sim.objects()
        assert len(objs) == 3 and {o.shape for o in objs} == {'cube', 'cylinder', 'sphere'}
        for i, o in enumerate(objs):
            assert 0.2 <= math.hypot(*o.position[:2]) <= 0.7
            assert 0.04 <= o.size <= 0.06
            for other in objs[i + 1:]:
                assert np.linalg.norm(o.position[:2] - other.position[:2]) >= 0.15


def test_n_objects_for_random_scenes():
    with Simulation('random_locations', seed=1, n_objects=6) as s:
        assert len(s.objects()) == 6


def test_lock_step_is_deterministic():
    rng = np.random.default_rng(7)
    commands = rng.uniform(-0.5, 0.5, size=(12, 6))
    runs = []
    for _ in range(2):
        with Simulation('random_locations', seed=5) as s:
            traj, images = [], []
            for i, v in enumerate(commands):
                s.set_joint_velocities(v)
                s.set_gripper(float(i % 2))
                s.step(24)
                traj.append(np.concatenate([s.joint_positions(), s.joint_velocities()]))
                if i % 4 == 0:
                    images.append(s.render_camera())
            runs.append((np.array(traj), images, [o.position for o in s.objects()]))
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][2], runs[1][2])
    for (rgb_a, d_a), (rgb_b, d_b) in zip(runs[0][1], runs[1][1], strict=True):
        np.testing.assert_array_equal(rgb_a, rgb_b)
        np.testing.assert_array_equal(d_a, d_b)


def test_trainer_robot_is_a_non_colliding_ghost_unseen_by_the_user_camera():
    with Simulation('set_locations', trainer_robot=True) as s, Simulation('set_locations') as ref:
        # trainer arm driven through the user's arm and the objects: no contacts at all
        s.set_joint_velocities(np.array([0.4, 1.0, 0.0, 0.3, 0.0, 0.0]), robot='trainer')
        s.step(int(1.5 * s.physics_hz))
        trainer = s._robot('trainer').body
        assert s._p.getContactPoints(bodyA=trainer) == ()
        assert np.linalg.norm(s.ee_pose('trainer')[0] - s.ee_pose('user')[0]) > 0.1
        np.testing.assert_allclose(s.joint_positions('user'), s.home_pose, atol=2e-3)
        ref.step(int(1.5 * ref.physics_hz))
        base = s._p.getBasePositionAndOrientation(trainer)
        rgb, _ = s.render_camera('user')
        rgb_ref, _ = ref.render_camera('user')
        assert np.abs(rgb.astype(int) - rgb_ref.astype(int)).max() <= 2
        # the trainer's arm is back in place after the render (PyBullet's base pose is the
        # inertial frame: putting back [0, 0, 0] once sank the arm 5 cm)
        np.testing.assert_allclose(s._p.getBasePositionAndOrientation(trainer)[0], base[0])
        # so at home, after renders of both views, the two arms coincide
        s.reset()
        s.render_camera('user')
        s.render_scene(64, 48)
        s.step(10)
        np.testing.assert_allclose(s.ee_pose('trainer')[0], s.ee_pose('user')[0], atol=1e-4)
        with pytest.raises(SimError, match='Unknown robot'):
            ref.joint_positions('trainer')


def test_inverse_kinematics_over_the_workspace(sim):
    for r in (0.2, 0.35, 0.5, 0.7):
        for angle in (-150, -60, 0, 90, 165):
            a = math.radians(angle)
            target = np.array([r * math.cos(a), r * math.sin(a), 0.03])
            quat = top_down_quat(a)
            q = sim.inverse_kinematics(target, quat)
            pos, orn = sim.forward_kinematics(q)
            assert np.linalg.norm(pos - target) < 0.003, (r, angle)
            assert abs(np.dot(orn, quat)) > 0.999
            assert np.all(q >= sim.lower) and np.all(q <= sim.upper)


def test_bad_commands_are_rejected(sim):
    sim.set_joint_velocities(np.full(6, 0.1))
    with pytest.raises(SimError, match='has 5 values but the arm has 6 joints'):
        sim.set_joint_velocities(np.zeros(5))
    with pytest.raises(SimError, match='NaN or inf'):
        sim.set_joint_velocities(np.array([0, 0, np.nan, 0, 0, 0]))
    np.testing.assert_allclose(sim.commanded_velocities(), np.full(6, 0.1))
    with pytest.raises(SimError, match='finite number'):
        sim.set_gripper(float('nan'))


def test_bad_construction_arguments():
    with pytest.raises(SimError, match='physics_hz must be a rate'):
        Simulation(physics_hz=0.0)
    with pytest.raises(SimError, match='Camera width must be an integer'):
        CameraConfig(width=0)
    with pytest.raises(SimError, match='Unknown scene'):
        Simulation(scene='no_such_scene')
    with pytest.raises(SimError, match='no random section'), Simulation('set_locations') as s:
        s.reset(new_random_draw=True)


def test_foreign_urdf_is_refused_with_the_missing_joints(tmp_path):
    urdf = tmp_path / 'arm.urdf'
    urdf.write_text(build_urdf().replace('joint_6', 'wrist_roll'))
    with pytest.raises(SimError, match=r"lacks the joints \['joint_6'\]"):
        Simulation(urdf=urdf)


def test_gui_without_display_is_refused(monkeypatch):
    monkeypatch.setenv('DISPLAY', '')
    with pytest.raises(SimError, match='gui=True needs a display'):
        Simulation(gui=True)


def test_collisions_with_the_ground_and_itself_are_reported(sim):
    assert sim.collisions() == []
    sim.set_joint_positions(np.array([0, 1.2, 1.2, 0, 0, 0]))   # wrist driven into the ground
    sim.step(5)
    assert any(c.endswith('- ground') for c in sim.collisions())
    sim.reset()
    sim.set_joint_positions(np.array([0.7, -0.41, 2.59, 2.5, 0.89, 0.92]))   # folded onto itself
    sim.step(1)
    assert 'link_2 - link_4' in sim.collisions()


def test_egl_renderer_sees_the_same_scene():
    # EGL (OpenGL) where the plugin loads, else a warning and TinyRenderer
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter('always')
        s = Simulation('set_locations', camera=CameraConfig(64, 64, renderer='egl'))
    try:
        if caught:
            assert 'EGL renderer plugin could not be loaded' in str(caught[0].message)
            assert s.camera.renderer == 'tiny'
        rgb, depth = s.render_camera()
        ys, xs = np.nonzero(colour_mask(rgb, 'red'))
        assert len(xs) > 5 and 22 <= xs.mean() <= 42
        assert 0.5 < float(np.median(depth[ys, xs])) < 0.7
    finally:
        s.close()


def test_connecting_prints_nothing(capfd):
    """pybullet printed ``argv[0]=`` (C stdout) twice per Simulation, so once per trial and
    client in every experiment log; the caller's own output stays as it was."""
    print('before', flush=True)
    for _ in range(2):
        Simulation('set_locations', seed=0, camera=CameraConfig(64, 64, 10.0)).close()
    print('after', flush=True)
    out, err = capfd.readouterr()
    assert 'argv[0]' not in out + err
    assert out == 'before\nafter\n'
