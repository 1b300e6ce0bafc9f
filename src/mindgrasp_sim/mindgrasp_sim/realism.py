"""Sensor noise and physical spread of a real arm, for the simulator (ROS-free).

A :class:`RealismProfile` (YAML: ``realism_profiles/<name>.yaml`` in this package, or any file)
lists how far the simulation departs from a perfect world; :class:`Realism` applies it with
seeded numpy ``Generator`` s. The :class:`~mindgrasp_sim.simulation.Simulation` owns one and
applies it where a real system has these effects, so the sim node, lock-step experiments and data
collection all see the same behaviour:

===========================  ===================================================================
model                        effect
===========================  ===================================================================
:class:`DepthNoise`          depth std ``sigma_base + sigma_z2 * z**2`` (m), quantisation in steps
                             ``max(quant_unit, quant_z2 * z**2)`` (m), invalid pixels (NaN or 0)
                             next to depth jumps, on dark or specular (saturated bright) surfaces,
                             out of range and at random
:class:`ColourNoise`         per-pixel noise (grey levels), exposure gain per frame, lighting gain
                             and colour tint per trial
:class:`CameraMountError`    the eye-in-hand camera sits off its URDF pose by a random offset (m)
                             and rotation (deg), fixed per trial: the controller's camera model is
                             wrong by that much
:class:`JointNoise`          encoder noise (rad, rad/s) and a fixed encoder offset per trial; the
                             joints follow the velocity command with a first-order lag (s)
:class:`ObjectSpread`        per trial and object: mass, friction and size scaled within ranges,
                             colour hue turned within a band (deg)
:class:`ContactSensing`      finger contact as a real hand reports it: ``any`` surface (the table
                             too), finger efforts (N m) with noise
===========================  ===================================================================

Typical use::

    profile = RealismProfile.load('default')          # or 'none', or a path to a YAML file
    realism = Realism(profile, seed=3)
    realism.begin_trial(layout_seed=0, trial=0)       # per-trial draws (camera error, lighting)
    depth = realism.depth_image(depth, rgb)           # float32 (H, W) m, NaN where invalid

Same profile, seed and trial, same draws: every random number comes from generators seeded by
``(seed, layout_seed, trial)``.
"""

from __future__ import annotations

import colorsys
import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from mindgrasp_common.cli_checks import yaml_error_text
from mindgrasp_common.resources import resource_path
from mindgrasp_sim.errors import SimError

__all__ = ['CameraMountError', 'ColourNoise', 'ContactSensing', 'DepthNoise', 'JointNoise',
           'ObjectSpread', 'Realism', 'RealismProfile', 'profile_dir']

_SPLIT = 0xFFFFFFFF


def profile_dir() -> Path:
    """Folder of the packaged profiles (``default.yaml``, ``none.yaml``)."""
    return resource_path('mindgrasp_sim', 'realism_profiles')


@dataclass(frozen=True)
class DepthNoise:
    """Depth camera (structured light / stereo) errors. Lengths in m, probabilities in 0..1.

    Attributes
    ----------
    sigma_base, sigma_z2 : float
        Noise standard deviation ``sigma_base + sigma_z2 * z**2`` at depth z (m); a D400-class
        stereo camera has about 1 mm at 0.3 m and 4 mm at 1 m.
    quant_unit, quant_z2 : float
        Depth is reported in steps of ``max(quant_unit, quant_z2 * z**2)`` (m): the driver's unit
        (1 mm) and the disparity step, which grows with z squared.
    min_range, max_range : float
        Closer or farther readings are invalid (m).
    edge_threshold : float
        A depth jump larger than this (m) between neighbours is an edge.
    edge_dropout, dark_dropout, specular_dropout, random_dropout : float
        Probability that a pixel next to an edge, on a dark surface (luminance below
        ``dark_level``), on a specular highlight (luminance above ``specular_level``), or any
        pixel, has no reading.
    dark_level, specular_level : float
        Luminance (0..1) thresholds of dark and specular surfaces.
    invalid : str
        How an invalid pixel is reported: ``'nan'`` (REP 118 float images) or ``'zero'``.
    """

    sigma_base: float = 0.0
    sigma_z2: float = 0.0
    quant_unit: float = 0.0
    quant_z2: float = 0.0
    min_range: float = 0.0
    max_range: float = math.inf
    edge_threshold: float = 0.02
    edge_dropout: float = 0.0
    dark_level: float = 0.12
    dark_dropout: float = 0.0
    specular_level: float = 0.97
    specular_dropout: float = 0.0
    random_dropout: float = 0.0
    invalid: str = 'nan'

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return any((self.sigma_base, self.sigma_z2, self.quant_unit, self.quant_z2,
                    self.min_range, self.edge_dropout, self.dark_dropout, self.specular_dropout,
                    self.random_dropout)) or math.isfinite(self.max_range)


@dataclass(frozen=True)
class ColourNoise:
    """Colour camera errors.

    sigma: per-pixel noise std (grey levels of 255); exposure_sigma: std of the per-frame
    log-gain (auto exposure hunting); lighting_gain: per-trial gain range [low, high] (room
    lighting); tint: per-trial per-channel gain spread (+/- fraction, white balance).
    """

    sigma: float = 0.0
    exposure_sigma: float = 0.0
    lighting_gain: tuple[float, float] = (1.0, 1.0)
    tint: float = 0.0

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return bool(self.sigma or self.exposure_sigma or self.tint
                    or tuple(self.lighting_gain) != (1.0, 1.0))


@dataclass(frozen=True)
class CameraMountError:
    """Calibration error of the eye-in-hand camera against the URDF, drawn once per trial:
    an offset of up to ``max_offset`` m in a random direction and a rotation of up to
    ``max_angle_deg`` about a random axis (both uniform in magnitude)."""

    max_offset: float = 0.0
    max_angle_deg: float = 0.0

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return bool(self.max_offset or self.max_angle_deg)


@dataclass(frozen=True)
class JointNoise:
    """Arm joint sensing and actuation.

    encoder_sigma: position noise std (rad) per reading; encoder_offset: per-trial fixed offset
    up to this (rad, uniform); velocity_sigma: velocity noise std (rad/s); lag: time constant (s)
    of the first-order lag with which the joints follow the velocity command (0: none).
    """

    encoder_sigma: float = 0.0
    encoder_offset: float = 0.0
    velocity_sigma: float = 0.0
    lag: float = 0.0

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return bool(self.encoder_sigma or self.encoder_offset or self.velocity_sigma or self.lag)


@dataclass(frozen=True)
class ObjectSpread:
    """Per-trial spread of the objects: scale ranges [low, high] of mass, friction (lateral,
    rolling and spinning together) and size, and the hue band (+/- deg) of their colour."""

    mass_scale: tuple[float, float] = (1.0, 1.0)
    friction_scale: tuple[float, float] = (1.0, 1.0)
    size_scale: tuple[float, float] = (1.0, 1.0)
    hue_deg: float = 0.0

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return bool(self.hue_deg) or any(tuple(r) != (1.0, 1.0) for r in (
            self.mass_scale, self.friction_scale, self.size_scale))


@dataclass(frozen=True)
class ContactSensing:
    """Finger sensing. mode ``'objects'``: a contact flag means "touches a scene object" (only a
    simulator knows that); ``'any'``: touches any surface, the table included, as a tactile
    sensor reports it. effort_sigma: noise std (N m) of the reported finger efforts."""

    mode: str = 'objects'
    effort_sigma: float = 0.0

    @property
    def enabled(self) -> bool:
        """True when the model changes anything."""
        return self.mode != 'objects' or bool(self.effort_sigma)


_SECTIONS = {'depth': DepthNoise, 'colour': ColourNoise, 'camera_mount': CameraMountError,
             'joints': JointNoise, 'objects': ObjectSpread, 'contacts': ContactSensing}


@dataclass(frozen=True)
class RealismProfile:
    """All realism models; every field defaults to "perfect" (the profile ``none``)."""

    name: str = 'none'
    depth: DepthNoise = field(default_factory=DepthNoise)
    colour: ColourNoise = field(default_factory=ColourNoise)
    camera_mount: CameraMountError = field(default_factory=CameraMountError)
    joints: JointNoise = field(default_factory=JointNoise)
    objects: ObjectSpread = field(default_factory=ObjectSpread)
    contacts: ContactSensing = field(default_factory=ContactSensing)

    def __post_init__(self) -> None:
        self.validate()

    @property
    def enabled(self) -> bool:
        """True when any model changes anything."""
        return any(getattr(self, s).enabled for s in _SECTIONS)

    def validate(self) -> None:
        """Raise :class:`SimError` naming the first bad value and how to fix it."""
        where = f'Realism profile {self.name!r}'
        for section in _SECTIONS:
            model = getattr(self, section)
            for f in dataclasses.fields(model):
                value = getattr(model, f.name)
                if isinstance(value, str):
                    continue
                values = value if isinstance(value, tuple) else (value,)
                bad = [v for v in values if not isinstance(v, (int, float)) or math.isnan(v)
                       or v < 0]
                if bad:
                    msg = (f'{where}: {section}.{f.name} must be a number >= 0 (or a range of '
                           f'them), got {value!r}; fix the profile YAML.')
                    raise SimError(msg)
                if isinstance(value, tuple) and (len(value) != 2 or value[0] > value[1]):
                    msg = (f'{where}: {section}.{f.name} must be a range [low, high] with low '
                           f'<= high, got {list(value)}.')
                    raise SimError(msg)
        for name in ('edge_dropout', 'dark_dropout', 'specular_dropout', 'random_dropout'):
            if getattr(self.depth, name) > 1:
                msg = f'{where}: depth.{name} is a probability in 0..1, got ' \
                      f'{getattr(self.depth, name)!r}.'
                raise SimError(msg)
        if self.depth.invalid not in ('nan', 'zero'):
            msg = f"{where}: depth.invalid must be 'nan' or 'zero', got {self.depth.invalid!r}."
            raise SimError(msg)
        if self.contacts.mode not in ('objects', 'any'):
            msg = f"{where}: contacts.mode must be 'objects' or 'any', got " \
                  f'{self.contacts.mode!r}.'
            raise SimError(msg)
        if self.objects.size_scale[0] <= 0 or self.objects.mass_scale[0] <= 0:
            msg = f'{where}: objects.size_scale and objects.mass_scale must stay > 0, got ' \
                  f'{list(self.objects.size_scale)} and {list(self.objects.mass_scale)}.'
            raise SimError(msg)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_dict(cls, data: dict[str, Any], name: str = 'custom') -> RealismProfile:
        """From a mapping ``{name:, depth: {...}, colour: {...}, ...}`` (the YAML layout)."""
        if not isinstance(data, dict):
            msg = f'Realism profile {name!r} must be a mapping of sections ' \
                  f'{sorted(_SECTIONS)}, got {type(data).__name__}.'
            raise SimError(msg)
        name = str(data.get('name', name))
        unknown = set(data) - {'name', *_SECTIONS}
        if unknown:
            msg = f'Realism profile {name!r}: unknown section(s) {sorted(unknown)}; allowed are ' \
                  f'name and {sorted(_SECTIONS)}.'
            raise SimError(msg)
        kwargs: dict[str, Any] = {'name': name}
        for section, model in _SECTIONS.items():
            values = data.get(section) or {}
            if not isinstance(values, dict):
                msg = f"Realism profile {name!r}: section '{section}' must be a mapping."
                raise SimError(msg)
            known = {f.name: f for f in dataclasses.fields(model)}
            unknown = set(values) - set(known)
            if unknown:
                msg = (f"Realism profile {name!r}: unknown field(s) {sorted(unknown)} in "
                       f"'{section}'; allowed are {sorted(known)}.")
                raise SimError(msg)
            fixed = {}
            for key, value in values.items():
                if isinstance(value, list):
                    value = tuple(value)
                elif isinstance(value, str) and key != 'mode' and key != 'invalid':
                    try:
                        value = float(value)     # YAML 'inf'
                    except ValueError:
                        msg = f"Realism profile {name!r}: {section}.{key} must be a number, " \
                              f'got {value!r}.'
                        raise SimError(msg) from None
                fixed[key] = value
            kwargs[section] = model(**fixed)
        return cls(**kwargs)

    @classmethod
    def load(cls, spec: str | Path | None) -> RealismProfile:
        """A profile by name (``'default'``, ``'none'``: packaged files) or YAML path; None and
        ``''`` mean ``'none'``."""
        if spec is None or str(spec) in ('', 'none'):
            return cls()
        path = Path(spec)
        if path.suffix not in ('.yaml', '.yml'):
            candidate = profile_dir() / f'{spec}.yaml'
            if not candidate.is_file():
                known = sorted(p.stem for p in profile_dir().glob('*.yaml'))
                msg = f'Unknown realism profile {str(spec)!r}; use one of {known} or a path to ' \
                      'a profile YAML file.'
                raise SimError(msg)
            path = candidate
        if not path.is_file():
            msg = f'Realism profile file {str(path)!r} does not exist; give an existing YAML ' \
                  'path, default or none.'
            raise SimError(msg)
        try:
            data = yaml.safe_load(path.read_text(encoding='utf-8'))
        except yaml.YAMLError as exc:
            msg = (f'Realism profile {str(path)!r} is not valid YAML '
                   f'({yaml_error_text(exc)}); fix its syntax.')
            raise SimError(msg) from None
        return cls.from_dict(data or {}, name=path.stem)

    def scaled(self, depth: float = 1.0, mount: float = 1.0) -> RealismProfile:
        """A copy with the depth noise std (``depth`` x) or the camera mount error (``mount``
        x) scaled: the one-factor sweeps of ``benchmarks/realism.py``."""
        d = dataclasses.replace(self.depth, sigma_base=self.depth.sigma_base * depth,
                                sigma_z2=self.depth.sigma_z2 * depth)
        m = dataclasses.replace(self.camera_mount, max_offset=self.camera_mount.max_offset * mount,
                                max_angle_deg=self.camera_mount.max_angle_deg * mount)
        return dataclasses.replace(self, depth=d, camera_mount=m)

    def only(self, *sections: str) -> RealismProfile:
        """A copy with every model but ``sections`` switched off (one factor at a time)."""
        unknown = set(sections) - set(_SECTIONS)
        if unknown:
            msg = f'Unknown realism section(s) {sorted(unknown)}; use {sorted(_SECTIONS)}.'
            raise SimError(msg)
        kwargs = {s: getattr(self, s) if s in sections else _SECTIONS[s]() for s in _SECTIONS}
        return RealismProfile(name=f'{self.name}[{",".join(sections)}]', **kwargs)


def _luminance(rgb: np.ndarray) -> np.ndarray:
    """Luminance 0..1 (H, W) of an rgb uint8 image (H, W, 3)."""
    return (rgb[..., 0] * 0.299 + rgb[..., 1] * 0.587 + rgb[..., 2] * 0.114) / 255.0


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix (3, 3) of ``angle`` rad about the unit ``axis`` (Rodrigues)."""
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def _unit(rng: np.random.Generator) -> np.ndarray:
    v = rng.normal(size=3)
    return v / max(float(np.linalg.norm(v)), 1e-12)


class Realism:
    """A :class:`RealismProfile` applied with seeded generators.

    Parameters
    ----------
    profile : RealismProfile | str | Path | None
        The profile, or its name / path for :meth:`RealismProfile.load`.
    seed : int
        Seed of every draw (per trial with :meth:`begin_trial`).
    n_joints : int
        Arm joints that get an encoder offset (6 or 7; the robot description's).

    Per-trial draws (set by :meth:`begin_trial`): ``mount_offset`` (3,) m and ``mount_rotation``
    (3, 3) in the camera's optical frame, ``lighting`` (3,) channel gains, ``encoder_offset``
    (n_joints,) rad. Per-reading noise comes from a second generator of the same trial.
    """

    def __init__(self, profile: RealismProfile | str | Path | None = None, seed: int = 0,
                 n_joints: int = 6) -> None:
        if not isinstance(profile, RealismProfile):
            profile = RealismProfile.load(profile)
        if not isinstance(seed, (int, np.integer)):
            msg = f'The realism seed must be an integer, got {seed!r}.'
            raise SimError(msg)
        self.profile = profile
        self.seed = int(seed)
        self.n_joints = int(n_joints)
        self.begin_trial(0, 0)

    @property
    def enabled(self) -> bool:
        """True when the profile changes anything."""
        return self.profile.enabled

    def begin_trial(self, layout_seed: int, trial: int) -> None:
        """Draw the per-trial quantities for a new trial (a reset of the simulation)."""
        seq = np.random.SeedSequence([self.seed & _SPLIT, int(layout_seed) & _SPLIT,
                                      int(trial) & _SPLIT])
        trial_seq, frame_seq = seq.spawn(2)
        self._trial_rng = np.random.default_rng(trial_seq)
        self.rng = np.random.default_rng(frame_seq)
        rng = self._trial_rng
        m = self.profile.camera_mount
        self.mount_offset = _unit(rng) * m.max_offset * rng.uniform()
        self.mount_rotation = _rotation(_unit(rng), math.radians(m.max_angle_deg) * rng.uniform())
        c = self.profile.colour
        gain = rng.uniform(*c.lighting_gain)
        self.lighting = gain * (1.0 + rng.uniform(-c.tint, c.tint, 3))
        j = self.profile.joints
        self.encoder_offset = rng.uniform(-j.encoder_offset, j.encoder_offset, self.n_joints)
        # objects are spread from their own generator, so the number of objects does not
        # change the other draws
        self._object_rng = np.random.default_rng(rng.integers(2 ** 63))

    # ------------------------------------------------------------------ objects
    def spread_object(self, spec: Any) -> Any:
        """A copy of an :class:`~mindgrasp_sim.scene.ObjectSpec` with this trial's mass,
        friction, size and hue (call once per object, in scene order)."""
        o = self.profile.objects
        if not o.enabled:
            return spec
        rng = self._object_rng
        size_k = rng.uniform(*o.size_scale)
        mass_k = rng.uniform(*o.mass_scale) * size_k ** 3     # same density, then spread
        fric_k = rng.uniform(*o.friction_scale)
        hue = rng.uniform(-o.hue_deg, o.hue_deg) / 360.0
        r, g, b, a = spec.rgba
        h, lum, s = colorsys.rgb_to_hls(r, g, b)
        rgba = (*colorsys.hls_to_rgb((h + hue) % 1.0, lum, s), a)
        size = spec.size * size_k
        pos = (spec.position[0], spec.position[1], spec.position[2] * size_k)
        return dataclasses.replace(
            spec, size=size, mass=spec.mass * mass_k, position=pos, rgba=rgba,
            friction=spec.friction * fric_k, rolling_friction=spec.rolling_friction * fric_k,
            spinning_friction=spec.spinning_friction * fric_k,
            scale=spec.scale * size_k if spec.shape == 'mesh' else spec.scale)

    # ------------------------------------------------------------------ camera
    def camera_pose(self, position: np.ndarray, rotation: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
        """The physical camera pose from its URDF pose: position (3,) m and rotation (3, 3)
        (columns = optical axes in the world) moved by this trial's mount error."""
        if not self.profile.camera_mount.enabled:
            return position, rotation
        return position + rotation @ self.mount_offset, rotation @ self.mount_rotation

    def colour_image(self, rgb: np.ndarray) -> np.ndarray:
        """Colour image uint8 (H, W, 3) as the camera delivers it (lighting, exposure, noise)."""
        c = self.profile.colour
        if not c.enabled:
            return rgb
        gain = self.lighting * math.exp(self.rng.normal(0.0, c.exposure_sigma)) \
            if c.exposure_sigma else self.lighting
        out = rgb.astype(np.float32) * gain.astype(np.float32)
        if c.sigma:
            out += self.rng.normal(0.0, c.sigma, rgb.shape).astype(np.float32)
        return np.clip(np.rint(out), 0, 255).astype(np.uint8)

    def depth_image(self, depth: np.ndarray, rgb: np.ndarray | None = None) -> np.ndarray:
        """Depth image float32 (H, W) m as the camera delivers it.

        ``rgb``: the registered colour image (uint8 (H, W, 3), before colour noise), whose
        luminance marks dark and specular surfaces.
        """
        d = self.profile.depth
        if not d.enabled:
            return depth
        rng = self.rng
        z = depth.astype(np.float32, copy=True)
        invalid = ~np.isfinite(z) | (z <= 0)
        z[invalid] = 0.0
        if d.sigma_base or d.sigma_z2:
            sigma = np.float32(d.sigma_base) + np.float32(d.sigma_z2) * z * z
            z += sigma * rng.standard_normal(z.shape, dtype=np.float32)
        if d.quant_unit or d.quant_z2:
            step = np.maximum(np.float32(d.quant_unit), np.float32(d.quant_z2) * z * z)
            step = np.maximum(step, np.float32(1e-6))
            z = np.rint(z / step) * step
        drop = np.zeros(z.shape, dtype=np.float32)
        if d.edge_dropout:
            jump = np.zeros(z.shape, dtype=bool)
            dz_x = np.abs(np.diff(depth, axis=1)) > d.edge_threshold
            dz_y = np.abs(np.diff(depth, axis=0)) > d.edge_threshold
            jump[:, 1:] |= dz_x
            jump[:, :-1] |= dz_x
            jump[1:, :] |= dz_y
            jump[:-1, :] |= dz_y
            drop = np.maximum(drop, jump * np.float32(d.edge_dropout))
        if rgb is not None and (d.dark_dropout or d.specular_dropout):
            lum = _luminance(rgb)
            drop = np.maximum(drop, (lum < d.dark_level) * np.float32(d.dark_dropout))
            drop = np.maximum(drop, (lum > d.specular_level) * np.float32(d.specular_dropout))
        if d.random_dropout:
            drop = np.maximum(drop, np.float32(d.random_dropout))
        if drop.any():
            invalid |= rng.random(z.shape, dtype=np.float32) < drop
        with np.errstate(invalid='ignore'):
            # the working range limits what can be measured at all (true depth)
            invalid |= (depth < d.min_range) | (depth > d.max_range)
        z[invalid] = np.nan if d.invalid == 'nan' else 0.0
        return z.astype(np.float32)

    # ------------------------------------------------------------------ joints and fingers
    def joint_readings(self, position: np.ndarray, velocity: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
        """Encoder readings of joint positions (n,) rad and velocities (n,) rad/s."""
        j = self.profile.joints
        q = np.asarray(position, dtype=float)
        v = np.asarray(velocity, dtype=float)
        if j.encoder_offset:
            q = q + self.encoder_offset[:q.size]
        if j.encoder_sigma:
            q = q + self.rng.normal(0.0, j.encoder_sigma, q.shape)
        if j.velocity_sigma:
            v = v + self.rng.normal(0.0, j.velocity_sigma, v.shape)
        return q, v

    def lagged_velocity(self, applied: np.ndarray, command: np.ndarray, dt: float) -> np.ndarray:
        """The joint velocity (n,) rad/s the arm follows after ``dt`` s: ``applied`` moved
        towards ``command`` with the time constant ``joints.lag`` (exact command when 0)."""
        lag = self.profile.joints.lag
        if lag <= 0:
            return np.asarray(command, dtype=float).copy()
        alpha = 1.0 - math.exp(-dt / lag)
        return applied + alpha * (np.asarray(command, dtype=float) - applied)

    def finger_efforts(self, efforts: np.ndarray) -> np.ndarray:
        """Finger effort readings (n,) N m."""
        s = self.profile.contacts.effort_sigma
        e = np.asarray(efforts, dtype=float)
        return e + self.rng.normal(0.0, s, e.shape) if s else e
