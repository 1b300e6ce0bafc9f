"""Realism profile: each noise source changes what it should, nothing else, and is seeded."""

from __future__ import annotations

import colorsys
import dataclasses
import math

import numpy as np
import pytest

from mindgrasp_sim.errors import SimError
from mindgrasp_sim.realism import (
    CameraMountError,
    ColourNoise,
    ContactSensing,
    DepthNoise,
    JointNoise,
    ObjectSpread,
    Realism,
    RealismProfile,
)
from mindgrasp_sim.scene import ObjectSpec
from mindgrasp_sim.simulation import Simulation


def only(**sections: object) -> RealismProfile:
    return RealismProfile(name='test', **sections)


# ---------------------------------------------------------------------------- profiles
def test_packaged_profiles() -> None:
    none = RealismProfile.load('none')
    assert not none.enabled
    assert RealismProfile.load(None) == none
    default = RealismProfile.load('default')
    assert default.name == 'default' and default.enabled
    for section in ('depth', 'colour', 'camera_mount', 'joints', 'objects', 'contacts'):
        assert getattr(default, section).enabled, section
    assert default.contacts.mode == 'any'


def test_profile_from_file_and_one_factor(tmp_path) -> None:
    f = tmp_path / 'lab.yaml'
    f.write_text('name: lab\ndepth: {sigma_z2: 0.004, max_range: 2.0}\n'
                 'objects: {mass_scale: [0.5, 2.0]}\n')
    p = RealismProfile.load(f)
    assert p.name == 'lab' and p.depth.sigma_z2 == 0.004 and p.objects.mass_scale == (0.5, 2.0)
    assert not p.colour.enabled
    depth_only = RealismProfile.load('default').only('depth')
    assert depth_only.depth.enabled and not depth_only.objects.enabled
    x2 = RealismProfile.load('default').scaled(depth=2.0, mount=0.0)
    assert x2.depth.sigma_z2 == 2 * RealismProfile.load('default').depth.sigma_z2
    assert not x2.camera_mount.enabled


@pytest.mark.parametrize(('text', 'match'), [
    ('depth: {sigma_z2: -1}', r'depth.sigma_z2 must be a number >= 0'),
    ('depth: {edge_dropout: 2}', r'depth.edge_dropout is a probability in 0..1'),
    ('depth: {sigma: 0.1}', r"unknown field\(s\) \['sigma'\] in 'depth'"),
    ('noise: {}', r"unknown section\(s\) \['noise'\]"),
    ('objects: {mass_scale: [2.0, 1.0]}', r'objects.mass_scale must be a range \[low, high\]'),
    ('contacts: {mode: table}', r"contacts.mode must be 'objects' or 'any'"),
    ('depth: {invalid: minus}', r"depth.invalid must be 'nan' or 'zero'"),
    ('depth: [1, 2', r'is not valid YAML'),
])
def test_bad_profiles_name_the_problem(tmp_path, text: str, match: str) -> None:
    f = tmp_path / 'bad.yaml'
    f.write_text(text)
    with pytest.raises(SimError, match=match):
        RealismProfile.load(f)


def test_unknown_profile_names_the_choices(tmp_path) -> None:
    with pytest.raises(SimError, match=r"Unknown realism profile 'realistic'; use one of "
                                       r"\['default', 'none'\]"):
        RealismProfile.load('realistic')
    with pytest.raises(SimError, match=r'does not exist'):
        RealismProfile.load(tmp_path / 'missing.yaml')


# ---------------------------------------------------------------------------- depth
def test_depth_noise_grows_with_distance_squared() -> None:
    r = Realism(only(depth=DepthNoise(sigma_base=0.0005, sigma_z2=0.0025)), seed=1)
    stds = {}
    for z in (0.3, 1.0, 2.0):
        out = r.depth_image(np.full((200, 200), z, np.float32))
        assert abs(float(out.mean()) - z) < 1e-3     # unbiased
        stds[z] = float(out.std())
    for z, s in stds.items():
        assert s == pytest.approx(0.0005 + 0.0025 * z * z, rel=0.05)


def test_depth_quantisation_and_range() -> None:
    r = Realism(only(depth=DepthNoise(quant_unit=0.001, quant_z2=0.0008, min_range=0.07,
                                      max_range=1.5)))
    depth = np.linspace(0.05, 2.0, 400, dtype=np.float32).reshape(20, 20)
    out = r.depth_image(depth)
    near = (depth >= 0.07) & (depth < 1.0)
    steps = out[near] / 0.001
    np.testing.assert_allclose(steps, np.rint(steps), atol=1e-3)   # whole millimetres
    assert np.all(np.abs(out[near] - depth[near]) <= 0.0005 + 1e-6)
    assert np.isnan(out[depth < 0.07]).all() and np.isnan(out[depth > 1.5]).all()
    far = (depth > 1.2) & (depth < 1.5)
    step = 0.0008 * depth[far] ** 2                         # the disparity step beyond 1.1 m
    assert np.all(np.abs(out[far] - depth[far]) <= step / 2 + 1e-5)


def test_invalid_pixels_at_edges_dark_and_specular_surfaces() -> None:
    depth = np.full((60, 60), 0.5, np.float32)
    depth[20:40, 20:40] = 0.4                     # a box 10 cm in front of the table
    rgb = np.full((60, 60, 3), 128, np.uint8)
    rgb[:10] = 5                                  # a dark stripe
    rgb[50:] = 255                                # a specular highlight
    edge = np.zeros((60, 60), bool)               # both sides of the jump (4-neighbours)
    edge[19:41, 20:40] = True
    edge[20:40, 19:41] = True
    edge[21:39, 21:39] = False
    profile = only(depth=DepthNoise(edge_dropout=1.0, dark_dropout=1.0, specular_dropout=1.0))
    out = Realism(profile).depth_image(depth, rgb)
    invalid = np.isnan(out)
    assert invalid[edge].all()
    assert invalid[:10].all() and invalid[50:].all()
    rest = ~edge
    rest[:10] = rest[50:] = False
    assert not invalid[rest].any()
    np.testing.assert_array_equal(out[rest], depth[rest])   # no other change
    zero = dataclasses.replace(profile.depth, invalid='zero')
    out0 = Realism(only(depth=zero)).depth_image(depth, rgb)
    assert (out0[invalid] == 0).all() and not np.isnan(out0).any()


def test_depth_noise_is_seeded() -> None:
    depth = np.full((50, 50), 0.6, np.float32)
    profile = RealismProfile.load('default')
    a = Realism(profile, seed=4).depth_image(depth)
    b = Realism(profile, seed=4).depth_image(depth)
    c = Realism(profile, seed=5).depth_image(depth)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(np.nan_to_num(a), np.nan_to_num(c))
    r = Realism(profile, seed=4)
    r.begin_trial(0, 1)                           # another trial, other draws
    assert not np.array_equal(np.nan_to_num(a), np.nan_to_num(r.depth_image(depth)))


# ---------------------------------------------------------------------------- colour
def test_colour_noise_lighting_and_exposure() -> None:
    rgb = np.full((80, 80, 3), 100, np.uint8)
    noisy = Realism(only(colour=ColourNoise(sigma=3.0)), seed=2).colour_image(rgb)
    assert float(noisy.std()) == pytest.approx(3.0, rel=0.1)
    assert abs(float(noisy.mean()) - 100) < 0.2
    lit = Realism(only(colour=ColourNoise(lighting_gain=(0.8, 0.8))), seed=2).colour_image(rgb)
    np.testing.assert_array_equal(lit, np.full_like(rgb, 80))
    r = Realism(only(colour=ColourNoise(exposure_sigma=0.05)), seed=2)
    means = [float(r.colour_image(rgb).mean()) for _ in range(20)]
    assert np.std(means) > 1.0                    # each frame its own exposure
    np.testing.assert_array_equal(
        Realism(RealismProfile.load('default'), 9).colour_image(rgb),
        Realism(RealismProfile.load('default'), 9).colour_image(rgb))


# ---------------------------------------------------------------------------- camera mount
def test_camera_mount_error_is_bounded_and_fixed_per_trial() -> None:
    r = Realism(only(camera_mount=CameraMountError(0.01, 2.0)), seed=3)
    seen = []
    for trial in range(20):
        r.begin_trial(0, trial)
        pos, rot = r.camera_pose(np.zeros(3), np.eye(3))
        angle = math.degrees(math.acos(np.clip((np.trace(rot) - 1) / 2, -1, 1)))
        assert np.linalg.norm(pos) <= 0.01 + 1e-12 and angle <= 2.0 + 1e-9
        np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=1e-12)
        p2, r2 = r.camera_pose(np.zeros(3), np.eye(3))       # fixed within the trial
        np.testing.assert_array_equal(pos, p2)
        np.testing.assert_array_equal(rot, r2)
        seen.append(np.linalg.norm(pos))
    assert max(seen) > 0.005 and len(set(seen)) == 20


# ---------------------------------------------------------------------------- joints
def test_encoder_noise_and_offset() -> None:
    r = Realism(only(joints=JointNoise(encoder_sigma=0.001, encoder_offset=0.002,
                                       velocity_sigma=0.01)), seed=0)
    q = np.linspace(-1, 1, 6)
    reads = np.array([r.joint_readings(q, np.zeros(6))[0] for _ in range(2000)])
    np.testing.assert_allclose(reads.std(axis=0), 0.001, rtol=0.1)
    offset = reads.mean(axis=0) - q
    np.testing.assert_allclose(offset, r.encoder_offset, atol=1e-4)
    assert np.all(np.abs(r.encoder_offset) <= 0.002) and np.any(np.abs(r.encoder_offset) > 1e-4)


def test_velocity_lag_is_first_order() -> None:
    r = Realism(only(joints=JointNoise(lag=0.05)))
    v = np.zeros(6)
    cmd = np.ones(6)
    for _ in range(12):                           # 0.05 s at 240 Hz
        v = r.lagged_velocity(v, cmd, 1 / 240)
    np.testing.assert_allclose(v, 1 - math.exp(-1), rtol=1e-6)
    assert np.array_equal(Realism().lagged_velocity(np.zeros(6), cmd, 1 / 240), cmd)


# ---------------------------------------------------------------------------- objects
def test_object_spread_within_ranges() -> None:
    spread = ObjectSpread(mass_scale=(0.6, 1.6), friction_scale=(0.6, 1.1),
                          size_scale=(0.95, 1.05), hue_deg=8.0)
    r = Realism(only(objects=spread), seed=7)
    spec = ObjectSpec('cube', 'yellow', 0.05, 0.075, (0.5, 0.0, 0.025),
                      rgba=(0.95, 0.9, 0.05, 1.0), friction=0.9)
    hue0 = colorsys.rgb_to_hls(*spec.rgba[:3])[0] * 360
    out = [r.spread_object(spec) for _ in range(200)]
    k = np.array([o.size / spec.size for o in out])
    assert k.min() >= 0.95 and k.max() <= 1.05
    mass = np.array([o.mass / spec.mass for o in out]) / k ** 3
    assert mass.min() >= 0.6 and mass.max() <= 1.6 and mass.std() > 0.2
    fr = np.array([o.friction / 0.9 for o in out])
    assert fr.min() >= 0.6 and fr.max() <= 1.1
    hues = np.array([colorsys.rgb_to_hls(*o.rgba[:3])[0] * 360 for o in out]) - hue0
    assert np.abs(hues).max() <= 8.0 + 1e-6 and np.abs(hues).max() > 6.0
    np.testing.assert_allclose([o.position[2] for o in out], [o.size / 2 for o in out])
    assert Realism().spread_object(spec) is spec


# ---------------------------------------------------------------------------- in the simulator
SCENE = {'name': 't', 'objects': [{'shape': 'cube', 'colour': 'red', 'position': [0.45, 0.0]}]}


@pytest.mark.slow
def test_simulation_sensors_are_seeded_and_ground_truth_stays_exact() -> None:
    default = RealismProfile.load('default')
    with Simulation(SCENE, realism=default, realism_seed=1) as a, \
            Simulation(SCENE, realism=default, realism_seed=1) as b, \
            Simulation(SCENE, realism=default, realism_seed=2) as c, Simulation(SCENE) as exact:
        ia, ib, ic = a.render_camera(), b.render_camera(), c.render_camera()
        np.testing.assert_array_equal(ia[0], ib[0])
        np.testing.assert_array_equal(ia[1], ib[1])
        assert not np.array_equal(ia[0], ic[0])
        rgb, depth = exact.render_camera()
        assert np.isnan(ia[1]).any() and not np.isnan(depth).any()
        assert not np.array_equal(ia[0], rgb)
        # the exact image of a realistic simulation: only the objects' spread differs
        ea = a.render_camera(exact=True)
        assert not np.isnan(ea[1]).any()
        np.testing.assert_array_equal(a.joint_positions(), exact.joint_positions())
        q, _ = a.joint_readings()
        assert 0 < np.max(np.abs(q - a.joint_positions())) < 0.01
        assert a.objects()[0].mass != exact.objects()[0].mass
        assert a.objects()[0].mass == b.objects()[0].mass


@pytest.mark.slow
def test_velocity_lag_in_the_simulation() -> None:
    lagging = only(joints=JointNoise(lag=0.1))
    with Simulation(SCENE, realism=lagging) as slow, Simulation(SCENE) as fast:
        for sim in (slow, fast):
            sim.set_joint_velocities(np.array([0.5, 0, 0, 0, 0, 0]))
            sim.step(24)                          # 0.1 s
        v_slow, v_fast = slow.joint_velocities()[0], fast.joint_velocities()[0]
        assert v_fast == pytest.approx(0.5, abs=0.03)
        assert v_slow == pytest.approx(0.5 * (1 - math.exp(-1)), abs=0.05)
        for sim in (slow, fast):
            sim.stop()
            sim.step(240)                         # 10 time constants
        assert abs(slow.joint_velocities()[0]) < 1e-3    # comes to rest after the lag


@pytest.mark.slow
def test_contacts_on_any_surface_and_finger_efforts() -> None:
    """A hand pressed on the empty table: a real tactile sensor reports contact, the perfect
    simulator's "touches an object" does not. A hand closed in the air has low finger efforts,
    one squeezing an object high ones (the grasp check's signal)."""
    from mindgrasp_sim.scripted import grasp_object_at, move_tcp_line
    from mindgrasp_sim.simulation import top_down_quat

    scene = {'name': 't', 'objects': [{'shape': 'cube', 'colour': 'red',
                                       'position': [0.3, 0.3]}]}
    any_surface = only(contacts=ContactSensing(mode='any'))
    for realism, expect in ((any_surface, True), (None, False)):
        with Simulation(scene, realism=realism) as sim:
            move_tcp_line(sim, np.array([0.5, 0.0, 0.005]), top_down_quat(0.0))
            sim.step(60)
            state = sim.gripper_state()
            assert state['contacts'].any() == expect
    with Simulation(SCENE, realism=RealismProfile.load('default')) as sim:
        sim.set_gripper(1.0)
        sim.step(240)
        assert np.all(np.abs(sim.gripper_state()['efforts']) < 0.4)      # closed on air
        sim.set_gripper(0.0)
        sim.step(240)
        assert grasp_object_at(sim, 0).success
        assert np.all(np.abs(sim.gripper_state()['efforts']) > 0.8)      # squeezing the cube
