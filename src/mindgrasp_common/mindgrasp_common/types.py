"""Plain data types exchanged between the MIndGrasp packages (no ROS).

- :class:`SceneObject`: one object of the task scene (simulator state, ``/sim/objects``).
- :class:`Prediction`: one decoded motor-imagery decision (``/bci/prediction``).
- :class:`CameraModel`: pinhole intrinsics of the eye-in-hand camera (``sensor_msgs/CameraInfo``).
- :class:`Recording`: continuous EEG with its cues, from a file, a bag or a stream.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import class_name

__all__ = ['CameraModel', 'Prediction', 'Recording', 'SceneObject']


def _identity_quat() -> np.ndarray:
    return np.array([0.0, 0.0, 0.0, 1.0])


@dataclass(frozen=True, eq=False)
class SceneObject:
    """One object of the scene.

    Attributes
    ----------
    object_id : int
        Index in the scene layout (``Marker.id``, ``TaskTarget.object_id``).
    colour, shape : str
        ``red`` / ``yellow`` / ``blue``; ``cube`` / ``cylinder`` / ``sphere`` (or ``unknown``).
    position : ndarray, shape (3,)
        Centre (m) in the frame of whoever built the object: the world for the simulator, the arm
        base frame (x forward at joint 1 = 0, y left) for the virtual subject.
    orientation : ndarray, shape (4,)
        Quaternion xyzw in the same frame.
    size : float
        Edge or diameter (m); 0 when unknown.
    mass : float
        kg; 0 when unknown.
    rgba : tuple of 4 float
        Display colour, 0..1.
    """

    object_id: int
    colour: str
    shape: str
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=_identity_quat)
    size: float = 0.0
    mass: float = 0.0
    rgba: tuple[float, float, float, float] = field(default=(1.0, 1.0, 1.0, 1.0), repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, 'position', np.asarray(self.position, dtype=float).reshape(3))
        object.__setattr__(self, 'orientation',
                           np.asarray(self.orientation, dtype=float).reshape(4))

    @property
    def label(self) -> str:
        """``"<colour> <shape>"``, as in ``GraspResult``, ``TaskTarget`` and ``FsmState``."""
        return f'{self.colour} {self.shape}'

    @property
    def x(self) -> float:
        """``position[0]`` (m)."""
        return float(self.position[0])

    @property
    def y(self) -> float:
        """``position[1]`` (m)."""
        return float(self.position[1])

    @property
    def z(self) -> float:
        """``position[2]`` (m)."""
        return float(self.position[2])


@dataclass(frozen=True, eq=False)
class Prediction:
    """One motor-imagery decision.

    Attributes
    ----------
    class_index : int
        :class:`mindgrasp_common.mi.MiClass` (0 left hand ... 3 both feet).
    certainty : float
        ``mean(distances) - min(distances)`` (paper Eq. 1, unbounded, >= 0).
    stamp : float
        Time of the last decoded sample (s, on the receiver's clock); NaN when not known.
    sample_index : int
        Stream index of the window's last sample; -1 when not known.
    distances : ndarray, shape (n_classes,), or None
        Per-class distances in the order of the model's classes, when the decoder gives them.
    probabilities : ndarray, shape (n_classes,), or None
        Calibrated class probabilities ``p(class | window)`` in the order of ``classes``, when
        the decoder gives them.
    classes : tuple of int, or None
        The decoder's class indices in the order of ``distances`` and ``probabilities`` (may
        include :data:`mindgrasp_common.mi.REST`).
    """

    class_index: int
    certainty: float
    stamp: float = math.nan
    sample_index: int = -1
    distances: np.ndarray | None = None
    probabilities: np.ndarray | None = None
    classes: tuple[int, ...] | None = None

    @property
    def class_name(self) -> str:
        """``'left_hand'`` ... ``'both_feet'``, or ``'rest'``."""
        return class_name(self.class_index)


@dataclass(frozen=True)
class CameraModel:
    """Pinhole intrinsics of a camera without distortion (``sensor_msgs/CameraInfo``), pixels.

    ``fx``, ``fy``: focal lengths; ``cx``, ``cy``: principal point, for an image of
    ``width`` x ``height`` px.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_k(cls, width: int, height: int, k: Sequence[float] | np.ndarray) -> CameraModel:
        """From the row-major 3x3 (or 9-vector) camera matrix ``K`` of a CameraInfo message.

        Raises
        ------
        CommonError
            ``K`` is not 9 values with ``fx``, ``fy`` > 0.
        """
        values = np.asarray(k, dtype=float).ravel()
        if values.size != 9 or not (values[0] > 0 and values[4] > 0):
            msg = (f'The camera matrix K {values.tolist()} is not a valid pinhole matrix (9 '
                   'values, fx, fy > 0); check the camera_info publisher.')
            raise CommonError(msg)
        return cls(int(width), int(height), float(values[0]), float(values[4]), float(values[2]),
                   float(values[5]))

    @classmethod
    def from_fov(cls, width: int, height: int, vertical_fov_deg: float) -> CameraModel:
        """Square pixels, principal point at the image centre, vertical field of view (deg)."""
        f = 0.5 * height / math.tan(math.radians(vertical_fov_deg) / 2.0)
        return cls(int(width), int(height), f, f, (width - 1) / 2.0, (height - 1) / 2.0)

    @property
    def k(self) -> np.ndarray:
        """The camera matrix K, shape (3, 3)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def scaled_to(self, width: int, height: int) -> CameraModel:
        """Intrinsics for an image of another size (same field of view)."""
        sx, sy = width / self.width, height / self.height
        return CameraModel(width, height, self.fx * sx, self.fy * sy, self.cx * sx, self.cy * sy)

    def backproject(self, u: float, v: float, depth: float) -> np.ndarray:
        """Point (3,) m in the optical frame (x right, y down, z forward) at pixel (u, v) and
        depth ``depth`` (m, along z)."""
        return np.array([(u - self.cx) / self.fx * depth, (v - self.cy) / self.fy * depth, depth])


def _no_events() -> np.ndarray:
    return np.zeros((0, 2), dtype=int)


@dataclass
class Recording:
    """Continuous EEG with its cues.

    Attributes
    ----------
    data : ndarray, shape (n_samples, n_channels)
        EEG in volts; NaN where samples were lost.
    rate : float
        Sampling rate (Hz).
    channels : list of str
        Channel labels, ``n_channels``.
    events : ndarray of int, shape (n_events, 2)
        ``[onset_sample, class_index]`` of each MI cue, onset relative to ``data[0]``.
    annotations : list of (float, float, str)
        The file's annotations: (onset s from the first sample, duration s, description).
    source : str
        File or bag the data came from.
    first_sample_index : int
        Stream index of ``data[0]`` (0 for files).
    n_aborted : int
        Cued trials left out of ``events`` because they were cut short (recorded runs).
    start_ns : int
        ROS time of ``data[0]`` (ns) for recorded runs; 0 when unknown (files).
    """

    data: np.ndarray
    rate: float
    channels: list[str]
    events: np.ndarray = field(default_factory=_no_events)
    annotations: list[tuple[float, float, str]] = field(default_factory=list)
    source: str = ''
    first_sample_index: int = 0
    n_aborted: int = 0
    start_ns: int = 0

    @property
    def duration(self) -> float:
        """Length (s)."""
        return len(self.data) / self.rate

    @property
    def n_missing(self) -> int:
        """Samples (rows) with a NaN: lost by the acquisition, or not finite in the file."""
        return int(np.isnan(self.data).any(axis=1).sum())
