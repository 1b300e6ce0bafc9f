"""Rendering of the simulation: the eye-in-hand RGB-D camera (:class:`CameraConfig`, its
intrinsics, the exact ground plane, leaving out arm links outside the view) and the third-person
scene view for people. :class:`~mindgrasp_sim.simulation.Simulation` inherits these methods; the
attributes they use are set by its constructor."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from mindgrasp_sim.arm_control import _Robot
from mindgrasp_sim.errors import SimError
from mindgrasp_sim.pybullet_quiet import BulletClient, pb
from mindgrasp_sim.realism import Realism
from mindgrasp_sim.world import GROUND_RGBA

#: growth (m) of a link's collision bounding box before the wrist camera leaves the link out
#: of a frame for lying outside its view (visual shapes may stick out of collision shapes)
CULL_MARGIN = 0.05
#: default third-person scene camera (m, world): behind-right of the base, looking at the objects
SCENE_EYE = (-0.55, -1.0, 0.9)
SCENE_TARGET = (0.25, 0.0, 0.3)
SKY_RGB = (70, 80, 100)
#: camera light: mostly ambient so the task colours stay saturated (original thresholds 0.7/0.3)
_LIGHT = {'lightDirection': [0.4, -0.3, 1.0], 'lightAmbientCoeff': 0.55,
          'lightDiffuseCoeff': 0.5, 'lightSpecularCoeff': 0.0}


@dataclass
class CameraConfig:
    """Eye-in-hand RGB-D camera settings.

    width, height: image size (px); rate_hz: publishing rate (Hz, used by the node);
    fov_deg: vertical field of view (deg); near, far: clipping planes (m); renderer: 'tiny'
    (PyBullet's CPU TinyRenderer, the default) or 'egl' (OpenGL through the EGL plugin: fast with a
    GPU, slow with a software driver; falls back to 'tiny' where EGL is missing).
    """

    width: int = 128
    height: int = 128
    rate_hz: float = 10.0
    fov_deg: float = 60.0
    near: float = 0.01
    far: float = 3.0
    renderer: str = 'tiny'


    def __post_init__(self) -> None:
        for name in ('width', 'height'):
            value = getattr(self, name)
            if not isinstance(value, (int, np.integer)) or not 8 <= value <= 4096:
                msg = f'Camera {name} must be an integer number of pixels in 8..4096, got ' \
                      f'{value!r}; use e.g. 128 or 640.'
                raise SimError(msg)
        if not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            msg = f'Camera rate_hz must be a positive number of Hz, got {self.rate_hz!r}; use ' \
                  'e.g. 10.0.'
            raise SimError(msg)
        if not 5.0 <= self.fov_deg <= 150.0:
            msg = f'Camera fov_deg must be in 5..150 degrees, got {self.fov_deg!r}.'
            raise SimError(msg)
        if self.renderer not in ('tiny', 'egl'):
            msg = f"Camera renderer must be 'tiny' or 'egl', got {self.renderer!r}."
            raise SimError(msg)
        if not 0 < self.near < self.far:
            msg = f'Camera clipping planes must satisfy 0 < near < far, got near={self.near!r}, ' \
                  f'far={self.far!r}.'
            raise SimError(msg)


class CameraMixin:
    """Wrist camera and scene view of :class:`~mindgrasp_sim.simulation.Simulation`: images
    rgb uint8 (H, W, 3), depth float32 (H, W) m along the optical axis."""

    # set by Simulation.__init__ (the renderer is a pybullet ER_* constant)
    _p: BulletClient
    _kin: BulletClient
    _robots: dict[str, _Robot]
    _renderer: int
    _ground_visual: bool
    _cull_enabled: bool
    _cull_tan: tuple[float, float]
    _visual_links: list[int]
    _visual_colours: dict[int, list[tuple[float, ...]]]
    _proj: object
    _rays: np.ndarray | None
    _ground_rgba: np.uint32
    camera: CameraConfig
    realism: Realism

    def _load_egl(self) -> int:
        import pkgutil
        import warnings

        loader = pkgutil.get_loader('eglRenderer')
        if loader is not None and self._p.loadPlugin(loader.get_filename(),
                                                     '_eglRendererPlugin') >= 0:
            return pb.ER_BULLET_HARDWARE_OPENGL
        warnings.warn('The EGL renderer plugin could not be loaded (no EGL on this machine); '
                      "rendering with TinyRenderer instead. Use camera renderer 'tiny'.",
                      stacklevel=3)
        self.camera.renderer = 'tiny'
        return pb.ER_TINY_RENDERER

    def _ground_colour(self) -> np.ndarray:
        """The ground's colour as TinyRenderer shades it under the camera light (rgb uint8)."""
        k = self._kin
        vis = k.createVisualShape(pb.GEOM_BOX, halfExtents=[0.5, 0.5, 0.005],
                                  visualFramePosition=[0, 0, -0.005], rgbaColor=GROUND_RGBA)
        body = k.createMultiBody(0, -1, vis, [10.0, 0, 0])
        view = k.computeViewMatrix([10.0, 0, 1.0], [10.0, 0, 0], [1, 0, 0])
        proj = k.computeProjectionMatrixFOV(20.0, 1.0, 0.1, 3.0)
        rgba = k.getCameraImage(8, 8, view, proj, renderer=pb.ER_TINY_RENDERER, shadow=0,
                                flags=pb.ER_NO_SEGMENTATION_MASK, **_LIGHT)[2]
        k.removeBody(body)
        return np.asarray(rgba, dtype=np.uint8).reshape(8, 8, 4)[4, 4, :3].copy()

    def camera_intrinsics(self) -> tuple[np.ndarray, int, int]:
        """Pinhole matrix K (3, 3) in pixels (ROS convention: pixel centres at integers), width,
        height."""
        c = self.camera
        fy = c.height / 2.0 / math.tan(math.radians(c.fov_deg) / 2.0)
        k = np.array([[fy, 0.0, (c.width - 1) / 2.0], [0.0, fy, (c.height - 1) / 2.0],
                      [0.0, 0.0, 1.0]])
        return k, c.width, c.height

    def render_camera(self, robot: str = 'user', exact: bool = False
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Render the eye-in-hand camera: rgb uint8 (H, W, 3) and depth float32 (H, W), metres
        along the optical axis (``far`` where nothing is hit).

        With a realism profile the image is what the camera delivers: seen from the camera's
        physical pose (mount error), with colour and depth noise and invalid depth pixels (NaN or
        0). ``exact=True`` renders the perfect image from the URDF pose.
        """
        c = self.camera
        p = self._p
        pos, orn = self.camera_pose(robot)
        rot = Rotation.from_quat(orn).as_matrix()
        sensed = not exact and robot == 'user' and self.realism.enabled
        if sensed:
            pos, rot = self.realism.camera_pose(pos, rot)
        target = pos + rot[:, 2]
        up = -rot[:, 1]
        view = p.computeViewMatrix(pos.tolist(), target.tolist(), up.tolist())
        if self._proj is None:
            self._proj = p.computeProjectionMatrixFOV(c.fov_deg, c.width / c.height, c.near, c.far)
        hidden = self._hide_other_robots(robot)
        culled = self._cull_links(robot, pos, rot)
        _, _, rgba, depth_buf, _ = p.getCameraImage(
            c.width, c.height, view, self._proj, renderer=self._renderer, shadow=0,
            flags=pb.ER_NO_SEGMENTATION_MASK, **_LIGHT)
        self._uncull(robot, culled)
        self._unhide(hidden)
        rgba = np.array(rgba, dtype=np.uint8, copy=True).reshape(c.height, c.width, 4)
        d = np.asarray(depth_buf, dtype=np.float32).reshape(c.height, c.width)
        depth = (c.far * c.near / (c.far - (c.far - c.near) * d)).astype(np.float32)
        if not self._ground_visual:
            self._draw_ground(rgba, depth, depth > c.far * 0.999, pos, rot)
        rgb = rgba[:, :, :3].copy()
        if sensed:
            depth = self.realism.depth_image(depth, rgb)
            rgb = self.realism.colour_image(rgb)
        return rgb, depth

    def _cull_links(self, robot: str, pos: np.ndarray, rot: np.ndarray) -> list[int]:
        """Make the links of ``robot`` that lie outside the camera's view invisible for one
        frame (alpha 0: TinyRenderer then skips their triangles) and return them.

        A wrist camera never sees most of its own arm, yet TinyRenderer transforms and clips
        every triangle of it: the xArm6's and the Panda's meshes cost 20-30 ms a frame. A link
        is left out when its bounding box (the collision shapes', grown by
        :data:`CULL_MARGIN` for visual shapes that stick out) lies wholly beyond one side of
        the view frustum, so the image is the same. pos (3,) m, rot (3, 3): the camera's
        optical frame in the world.
        """
        if not self._cull_enabled or robot != 'user':
            return []
        body = self._robots[robot].body
        p = self._p
        links = self._visual_links
        boxes = np.array([p.getAABB(body, link) for link in links])          # (L, 2, 3) m
        boxes[:, 0] -= CULL_MARGIN
        boxes[:, 1] += CULL_MARGIN
        corners = boxes[:, _BOX_CORNERS, _XYZ]                                # (L, 8, 3)
        seen = _boxes_in_view((corners - pos) @ rot, self.camera.near, self._cull_tan)
        culled = [link for link, s in zip(links, seen, strict=True) if not s]
        for link in culled:
            p.changeVisualShape(body, link, rgbaColor=[1.0, 1.0, 1.0, 0.0])
        return culled

    def _uncull(self, robot: str, culled: list[int]) -> None:
        """Give the links :meth:`_cull_links` hid their colours back (each visual shape's)."""
        body = self._robots[robot].body
        for link in culled:
            for k, colour in enumerate(self._visual_colours[link]):
                self._p.changeVisualShape(body, link, shapeIndex=k, rgbaColor=colour)

    def _draw_ground(self, rgba: np.ndarray, depth: np.ndarray, empty: np.ndarray,
                     pos: np.ndarray, rot: np.ndarray) -> None:
        """Fill pixels that hit nothing with the ground plane z = 0 (exact ray-plane depth).

        rgba: (H, W, 4) uint8, C-contiguous; depth: (H, W) float32 m; empty: (H, W) bool.
        """
        if self._rays is None:
            k, w, h = self.camera_intrinsics()
            u, v = np.meshgrid(np.arange(w, dtype=float), np.arange(h, dtype=float))
            # optical-frame ray of each pixel with depth 1: (x, y, 1)
            self._rays = np.stack([(u - k[0, 2]) / k[0, 0],
                                   (v - k[1, 2]) / k[1, 1]]).astype(np.float32)
            colour = np.array([*self._ground_colour(), 255], dtype=np.uint8)
            self._ground_rgba = colour.view(np.uint32)[0]
        # world z component of each ray, then the depth at which it meets z = 0
        r = rot[2].astype(np.float32)
        rz = self._rays[0] * r[0] + self._rays[1] * r[1] + r[2]
        with np.errstate(divide='ignore', invalid='ignore'):
            t = np.float32(-pos[2]) / rz
        hit = empty & (rz < 0) & (t <= self.camera.far)
        np.copyto(depth, t, where=hit)
        # one 32-bit word per pixel: a masked fill instead of a per-channel scatter
        np.copyto(rgba.view(np.uint32).reshape(hit.shape), self._ground_rgba, where=hit)

    def render_scene(self, width: int = 320, height: int = 240,
                     eye: tuple[float, float, float] = SCENE_EYE,
                     target: tuple[float, float, float] = SCENE_TARGET,
                     fov_deg: float = 50.0) -> np.ndarray:
        """Render a third-person view of the scene for people (the participant's screen).

        Both arms are drawn; the training robot (when loaded) is blended at 50 % over what is
        behind it, so it looks green and semi-transparent (TinyRenderer ignores alpha, so the
        view is rendered twice: without and with the training robot). Pixels that hit nothing
        show the ground plane (z = 0) or, above the horizon, a plain sky.

        Parameters
        ----------
        width, height : int
            Image size (px), 8..4096.
        eye, target : (x, y, z)
            Camera position and the point it looks at (m, world frame; z up).
        fov_deg : float
            Vertical field of view (deg).

        Returns
        -------
        rgb : ndarray of uint8, shape (height, width, 3)
        """
        for name, value in (('width', width), ('height', height)):
            if not isinstance(value, (int, np.integer)) or not 8 <= value <= 4096:
                msg = (f'Scene camera {name} must be an integer number of pixels in 8..4096, got '
                       f'{value!r}; use e.g. 320x240.')
                raise SimError(msg)
        p = self._p
        near, far = 0.05, 6.0
        view = p.computeViewMatrix(list(eye), list(target), [0.0, 0.0, 1.0])
        proj = p.computeProjectionMatrixFOV(fov_deg, width / height, near, far)
        kw = {'renderer': self._renderer, 'shadow': 0, **_LIGHT}
        ghost = self._robots.get('trainer')
        hidden = self._hide_other_robots('user') if ghost is not None else []
        _, _, rgba, depth_buf, _ = p.getCameraImage(width, height, view, proj,
                                                    flags=pb.ER_NO_SEGMENTATION_MASK, **kw)
        self._unhide(hidden)
        rgb = np.array(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3].copy()
        empty = np.asarray(depth_buf, dtype=np.float32).reshape(height, width) > 0.9999
        self._scene_background(rgb, empty, np.asarray(eye, float), np.asarray(target, float),
                               fov_deg)
        if ghost is not None:
            _, _, rgba2, _, seg = p.getCameraImage(width, height, view, proj, **kw)
            seg = np.asarray(seg, dtype=np.int64).reshape(height, width)
            mask = (seg >= 0) & ((seg & ((1 << 24) - 1)) == ghost.body)
            over = np.asarray(rgba2, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
            rgb[mask] = ((rgb[mask].astype(np.uint16) + over[mask]) // 2).astype(np.uint8)
        return rgb

    def _scene_background(self, rgb: np.ndarray, empty: np.ndarray, eye: np.ndarray,
                          target: np.ndarray, fov_deg: float) -> None:
        """Paint ``empty`` pixels of a scene view (rgb (H, W, 3) uint8) as ground or sky."""
        h, w = empty.shape
        forward = target - eye
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        f = h / 2.0 / math.tan(math.radians(fov_deg) / 2.0)
        u = (np.arange(w) - (w - 1) / 2.0) / f
        v = (np.arange(h) - (h - 1) / 2.0) / f
        # world z of the ray through each pixel (image v grows downwards)
        rz = forward[2] + u[None, :] * right[2] - v[:, None] * up[2]
        ground = empty & (rz < 0)
        rgb[ground] = np.asarray(GROUND_RGBA[:3]) * 255 * 0.85
        rgb[empty & ~ground] = SKY_RGB

    def _hide_other_robots(self, robot: str) -> list[tuple[int, tuple, tuple]]:
        # the trainer's ghost arm is seen by people, not by the user's camera: park it below
        # the ground while rendering (it collides with nothing, so physics is unaffected)
        hidden = []
        for name, r in self._robots.items():
            if name != robot and name == 'trainer':
                # PyBullet's base pose is the base's inertial frame, not its URDF link frame:
                # put back exactly what was read (restoring [0, 0, 0] sank the ghost 5 cm)
                pos, orn = self._p.getBasePositionAndOrientation(r.body)
                self._p.resetBasePositionAndOrientation(r.body, [0, 0, -5.0], [0, 0, 0, 1])
                hidden.append((r.body, pos, orn))
        return hidden

    def _unhide(self, hidden: list[tuple[int, tuple, tuple]]) -> None:
        for body, pos, orn in hidden:
            self._p.resetBasePositionAndOrientation(body, pos, orn)


#: the 8 corners of a box (lower, upper) as indices into its (2, 3) bounds, and the 12 edges
#: between corners numbered by bits (x: 4, y: 2, z: 1)
_BOX_CORNERS = np.array([[(i >> 2) & 1, (i >> 1) & 1, i & 1] for i in range(8)])
_XYZ = np.arange(3)
_BOX_EDGES = np.array([(i, i | bit) for i in range(8) for bit in (1, 2, 4) if not i & bit])


def _boxes_in_view(cam: np.ndarray, near: float, tan: tuple[float, float]) -> np.ndarray:
    """Whether each box, corners ``cam`` (L, 8, 3) m in a camera's optical frame (z forward),
    may show in its image: the part of the box beyond the near plane ``near`` m, projected,
    meets the image's rectangle of half-widths ``tan`` (x, y). Conservative (the projection's
    bounding rectangle stands for the projection). Returns (L,) bool."""
    z = cam[..., 2]
    ahead = z > near                                                       # (L, 8)
    a, b = cam[:, _BOX_EDGES[:, 0]], cam[:, _BOX_EDGES[:, 1]]              # (L, 12, 3)
    cross = ahead[:, _BOX_EDGES[:, 0]] != ahead[:, _BOX_EDGES[:, 1]]       # (L, 12)
    dz = b[..., 2] - a[..., 2]
    t = np.where(cross, (near - a[..., 2]) / np.where(cross, dz, 1.0), 0.0)
    pts = np.concatenate([cam, a + t[..., None] * (b - a)], axis=1)        # (L, 20, 3)
    valid = np.concatenate([ahead, cross], axis=1)
    zs = np.where(valid, pts[..., 2], 1.0)
    u, v = pts[..., 0] / zs, pts[..., 1] / zs
    inf = np.inf
    return (ahead.any(axis=1)
            & (np.where(valid, u, inf).min(axis=1) <= tan[0])
            & (np.where(valid, u, -inf).max(axis=1) >= -tan[0])
            & (np.where(valid, v, inf).min(axis=1) <= tan[1])
            & (np.where(valid, v, -inf).max(axis=1) >= -tan[1]))
