"""Depth images of single objects from the PyBullet simulator, labelled from the scene objects.

Each sample is one scene with a target object (random shape - balanced - colour, size, yaw and
place in front of the arm, sometimes with distractor objects nearby) seen by the eye-in-hand
camera from a random pre-final-approach pose: the arm is placed by inverse kinematics so that the
camera looks at the object from 0.12-0.40 m, 20-90 deg above the horizon, from the robot's side,
with some roll and off-centre aim. The object is found with the same :class:`ColourDetector` the
node uses, and :func:`~mindgrasp_vision.shape_cnn.preprocess_depth` makes the network input; the
label is the target's shape as the simulator knows it. Same seed, same data set.

With a realism profile (``realism='default'``) the images are those of a real camera (depth noise,
invalid pixels, mount error, lighting, object spread; :mod:`mindgrasp_sim.realism`), and the depth
goes through the same :class:`~mindgrasp_vision.depth.DepthFilter` as in the vision pipeline. Each
view is a trial of its own for the realism draws (its own mount error, lighting and noise field).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.depth import DepthFilter
from mindgrasp_vision.detector import CameraModel, ColourDetector, Detection
from mindgrasp_vision.shape_cnn import SHAPES, Preprocessing, preprocess_depth

__all__ = ['CameraPlacer', 'DatasetConfig', 'ShapeDataset', 'collect_shape_dataset',
           'look_at_rotation', 'match_detection']


@dataclass(frozen=True)
class DatasetConfig:
    """Ranges of the random views (m, degrees)."""

    distance: tuple[float, float] = (0.10, 0.40)     # camera to object centre
    elevation_deg: tuple[float, float] = (20.0, 90.0)
    azimuth_jitter_deg: float = 25.0                   # around "seen from the base"
    roll_deg: float = 20.0
    aim_jitter: float = 0.25                           # off-centre aim, fraction of the distance
    radius: tuple[float, float] = (0.25, 0.60)         # object distance from the base axis
    angle_deg: tuple[float, float] = (-60.0, 60.0)
    size: tuple[float, float] = (0.04, 0.06)
    colours: tuple[str, ...] = ('red', 'yellow', 'blue')
    distractor_probability: float = 0.5
    min_pixel_fraction: float = 0.01


@dataclass
class ShapeDataset:
    """Network inputs and labels.

    x : ndarray, shape (n, size, size), float32 - preprocessed depth crops
    y : ndarray, shape (n,), int64 - indices into :data:`~mindgrasp_vision.shape_cnn.SHAPES`
    info : list of dict - per sample: colour, size (m), camera distance (m), elevation (deg),
        pixel fraction, the view's camera mount error (mm, 3; zeros without realism)
    """

    x: np.ndarray
    y: np.ndarray
    info: list[dict] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.y)

    def save(self, path: str | Path) -> None:
        """Write an .npz (x, y) file."""
        np.savez_compressed(path, x=self.x, y=self.y)

    @classmethod
    def load(cls, path: str | Path) -> ShapeDataset:
        """Read an .npz written by :meth:`save`."""
        try:
            with np.load(path) as f:
                return cls(f['x'].astype(np.float32), f['y'].astype(np.int64))
        except (OSError, KeyError, ValueError) as exc:
            msg = f'Cannot read the shape data set {path} ({exc}); collect it again.'
            raise VisionError(msg) from exc


def look_at_rotation(camera: np.ndarray, target: np.ndarray, roll: float = 0.0) -> np.ndarray:
    """Rotation (3, 3), columns = optical frame axes (x right, y down, z forward) in the world,
    of a camera at ``camera`` looking at ``target`` with image "right" horizontal (then rolled
    by ``roll`` rad about the optical axis)."""
    z = np.asarray(target, float) - np.asarray(camera, float)
    z /= np.linalg.norm(z)
    horiz = np.array([z[0], z[1], 0.0])
    if np.linalg.norm(horiz) < 1e-6:   # looking straight down: right is perpendicular to radial
        horiz = np.array([camera[0], camera[1], 0.0])
        if np.linalg.norm(horiz) < 1e-6:
            horiz = np.array([1.0, 0.0, 0.0])
    horiz /= np.linalg.norm(horiz)
    right = np.cross(horiz, [0.0, 0.0, 1.0])
    x = right - right.dot(z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    c, s = math.cos(roll), math.sin(roll)
    return np.column_stack([c * x + s * y, -s * x + c * y, z])


class CameraPlacer:
    """Put the simulated arm where its eye-in-hand camera looks at a point (inverse kinematics).

    Parameters
    ----------
    sim : mindgrasp_sim.simulation.Simulation
        The simulation whose user arm is moved (teleported with ``set_joint_positions``).
    """

    def __init__(self, sim: object) -> None:
        from scipy.spatial.transform import Rotation

        self.sim = sim
        # fixed transform camera -> TCP (both on the palm), from forward kinematics at home
        cam_p, cam_q = sim.forward_kinematics(sim.home_pose, 'camera')
        tcp_p, tcp_q = sim.forward_kinematics(sim.home_pose, 'tcp')
        r_cam = Rotation.from_quat(cam_q)
        self._rot = r_cam.inv() * Rotation.from_quat(tcp_q)
        self._pos = r_cam.inv().apply(tcp_p - cam_p)
        self.camera_position, self.camera_rotation = np.zeros(3), np.eye(3)

    def look_at(self, target: np.ndarray, distance: float, elevation_deg: float,
                azimuth_deg: float | None = None, roll_deg: float = 0.0,
                aim: np.ndarray | None = None, tolerance: float = 0.02) -> bool:
        """Move the arm so that the camera, ``distance`` m from ``target`` and ``elevation_deg``
        above it, looks at ``aim`` (default ``target``).

        ``azimuth_deg``: horizontal direction from the target to the camera (world frame, deg);
        None places the camera on the base's side of the target. Returns False when the arm
        cannot reach the view within ``tolerance`` m / 8 deg (the arm is then not moved).
        """
        from scipy.spatial.transform import Rotation

        target = np.asarray(target, dtype=float)
        if azimuth_deg is None:
            azimuth_deg = math.degrees(math.atan2(target[1], target[0])) + 180.0
        az, elev = math.radians(azimuth_deg), math.radians(elevation_deg)
        cam = target + distance * np.array([math.cos(elev) * math.cos(az),
                                            math.cos(elev) * math.sin(az), math.sin(elev)])
        rot = Rotation.from_matrix(look_at_rotation(
            cam, target if aim is None else np.asarray(aim, float), math.radians(roll_deg)))
        sim = self.sim
        q = sim.inverse_kinematics(cam + rot.apply(self._pos), (rot * self._rot).as_quat(),
                                   seed_q=sim.home_pose)
        got_p, got_q = sim.forward_kinematics(q, 'camera')
        ang = (Rotation.from_quat(got_q).inv() * rot).magnitude()
        if np.linalg.norm(got_p - cam) > tolerance or ang > math.radians(8):
            return False
        sim.set_joint_positions(q)
        self.camera_position = np.asarray(got_p, dtype=float)
        self.camera_rotation = Rotation.from_quat(got_q).as_matrix()
        return True

    def project(self, point: np.ndarray) -> tuple[float, float, float]:
        """Pixel (u, v) and depth z (m) of a world point in the current camera image."""
        k, _, _ = self.sim.camera_intrinsics()
        pc = self.camera_rotation.T @ (np.asarray(point, float) - self.camera_position)
        z = float(pc[2])
        if z <= 1e-6:
            return math.nan, math.nan, z
        return k[0, 0] * pc[0] / z + k[0, 2], k[1, 1] * pc[1] / z + k[1, 2], z


def match_detection(dets: list[Detection], colour: str, uv: tuple[float, float]
                    ) -> Detection | None:
    """The detection of ``colour`` whose box holds pixel ``uv`` (nearest centre), or None."""
    best, best_d = None, math.inf
    for d in dets:
        if d.colour != colour:
            continue
        x, y, w, h = d.bbox
        inside = x - 2 <= uv[0] <= x + w + 2 and y - 2 <= uv[1] <= y + h + 2
        dist = math.hypot(d.centre[0] - uv[0], d.centre[1] - uv[1])
        if inside and dist < best_d:
            best, best_d = d, dist
    return best


def collect_shape_dataset(n_images: int, seed: int = 0, config: DatasetConfig = DatasetConfig(),
                          prep: Preprocessing | None = None, image_size: int = 128,
                          progress: Callable[[int, int], None] | None = None,
                          realism: object = None, depth_filter: DepthFilter | None = None
                          ) -> ShapeDataset:
    """Render ``n_images`` labelled depth crops (balanced over the shapes) in the simulator.

    Parameters
    ----------
    n_images : int
        Samples to collect.
    seed : int
        Seed of every random choice; same seed, same data set.
    config : DatasetConfig
        View and scene ranges.
    prep : Preprocessing | None
        Network input preprocessing (default :class:`Preprocessing`).
    image_size : int
        Camera image width = height (px).
    progress : callable (done, total) | None
        Called after each sample.
    realism : RealismProfile | str | None
        Realism profile of the simulated camera (name, path or profile; None: a perfect camera);
        its draws are seeded by ``seed``.
    depth_filter : DepthFilter | None
        Depth clean-up before detection (default: the vision pipeline's, a 3 px median).
    """
    from mindgrasp_sim.camera import CameraConfig
    from mindgrasp_sim.simulation import Simulation

    if n_images < 1:
        msg = f'n_images must be >= 1, got {n_images}; the paper used about 500.'
        raise VisionError(msg)
    prep = prep or Preprocessing()
    rng = np.random.default_rng(seed)
    first = {'name': 'vision_dataset',
             'objects': [{'shape': 'cube', 'colour': 'red', 'position': [0.5, 0.0]}]}
    sim = Simulation(scene=first, seed=seed,
                     camera=CameraConfig(width=image_size, height=image_size),
                     realism=realism, realism_seed=seed)
    depth_filter = depth_filter or DepthFilter()
    try:
        k, width, height = sim.camera_intrinsics()
        detector = ColourDetector(intrinsics=CameraModel.from_k(width, height, k))
        placer = CameraPlacer(sim)
        xs, ys, info = [], [], []
        attempts = 0
        while len(ys) < n_images:
            attempts += 1
            if attempts > 20 * n_images + 100:
                msg = (f'Only {len(ys)} of {n_images} views succeeded in {attempts} attempts; '
                       'widen the DatasetConfig ranges (the arm cannot reach these views).')
                raise VisionError(msg)
            sample = _draw_scene(rng, config, SHAPES[len(ys) % len(SHAPES)])
            # the attempt number is the view's layout seed: the realism draws (camera mount
            # error, lighting, depth noise and dropout) come from (realism seed, layout seed,
            # trial), so with the scene's fixed seed every view had the same mount error and
            # the very same noise field, which the network learnt (99 % validation, 93 % on a
            # test set with another field). Without realism the seed changes nothing.
            sim.load_scene(sample['scene'], seed=attempts)
            target = np.array(sample['target'])
            # camera on a sphere round the object, on the base's side of it
            d = rng.uniform(*config.distance)
            elev = rng.uniform(*config.elevation_deg)
            bearing = math.degrees(math.atan2(target[1], target[0])) + 180.0
            az = bearing + rng.uniform(-1, 1) * config.azimuth_jitter_deg
            aim = target + rng.uniform(-1, 1, 3) * config.aim_jitter * d * np.array([1, 1, 0.5])
            roll = rng.uniform(-1, 1) * config.roll_deg
            if not placer.look_at(target, d, elev, az, roll, aim):
                continue  # out of reach
            rgb, depth = sim.render_camera()
            depth = depth_filter(depth)
            u, v, z = placer.project(target)
            if z <= 0.02:
                continue
            det = match_detection(detector.detect(rgb, depth), sample['colour'], (u, v))
            if det is None or det.truncated or det.pixel_fraction < config.min_pixel_fraction:
                continue
            try:
                x = preprocess_depth(depth, det.bbox, det.mask, prep)
            except VisionError:
                continue
            label = next(o.shape for o in sim.objects() if o.object_id == 0)  # from the simulator
            xs.append(x)
            ys.append(SHAPES.index(label))
            info.append({'colour': sample['colour'], 'size': sample['size'],
                         'distance': round(float(d), 4), 'elevation_deg': round(float(elev), 2),
                         'pixel_fraction': round(det.pixel_fraction, 5),
                         'camera_mount_offset_mm': [round(1000 * float(v), 3)
                                                    for v in sim.realism.mount_offset]})
            if progress is not None:
                progress(len(ys), n_images)
    finally:
        sim.close()
    return ShapeDataset(np.stack(xs).astype(np.float32), np.array(ys, dtype=np.int64), info)


def _draw_scene(rng: np.random.Generator, config: DatasetConfig, shape: str) -> dict:
    colour = str(config.colours[int(rng.integers(len(config.colours)))])
    size = float(rng.uniform(*config.size))
    r = float(rng.uniform(*config.radius))
    a = math.radians(rng.uniform(*config.angle_deg))
    xy = [r * math.cos(a), r * math.sin(a)]
    objects = [{'shape': shape, 'colour': colour, 'size': size, 'position': xy,
                'yaw_deg': float(rng.uniform(0, 90))}]
    if rng.random() < config.distractor_probability:
        for _ in range(int(rng.integers(1, 3))):
            for _ in range(20):
                dr, da = rng.uniform(0.09, 0.2), rng.uniform(0, 2 * math.pi)
                p = [xy[0] + dr * math.cos(da), xy[1] + dr * math.sin(da)]
                if all(math.dist(p, o['position']) >= 0.08 for o in objects):
                    objects.append({
                        'shape': str(SHAPES[int(rng.integers(3))]),
                        'colour': str(config.colours[int(rng.integers(len(config.colours)))]),
                        'size': float(rng.uniform(*config.size)), 'position': p,
                        'yaw_deg': float(rng.uniform(0, 90))})
                    break
    return {'scene': {'name': 'vision_dataset', 'objects': objects}, 'target':
            [xy[0], xy[1], size / 2], 'colour': colour, 'size': size}
