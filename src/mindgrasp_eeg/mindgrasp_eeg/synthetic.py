"""Synthetic EEG with motor-imagery signatures, generated chunk by chunk (units: volts).

The signal at the electrodes is the sum of

- a spatially correlated 1/f ("pink") background: independent pink noise per electrode smoothed
  over the scalp with an exponential distance kernel,
- rhythmic sources (band-limited noise, so amplitude waxes and wanes as in real EEG): occipital
  alpha (8-12 Hz) and, for each sensorimotor area, mu (9-13 Hz) and beta (18-26 Hz),
- optional artefacts: eye blinks (frontal, ~100 uV, 300 ms) and EMG bursts (broad-band, temporal),
  optional mains interference,
- white sensor noise.

Motor imagery is event-related desynchronisation (ERD): while a class is imagined, mu and beta
amplitude of the sources over the matching motor area drop by ``erd_depth`` (smoothly, with time
constant ``erd_tau``). Sources sit under C4 (left hand), C3 (right hand), both (both hands) and the
vertex Cz (feet), and reach the electrodes through a fixed dipole head model (:class:`HeadModel`),
so each class changes the spatial covariance as real MI does.

How decodable the subject is, is set by four numbers (their defaults reproduce the original
generator bit for bit; :mod:`~mindgrasp_experiments.decodability` measures and fits them):

- ``separability`` scales the ERD depth of every class (1: ``erd_depth``, 0: imagery changes
  nothing over the motor cortex, so no class can be told from another);
- ``lateral_separability`` is how lateralised a one-hand ERD is (1: only the contralateral
  hemisphere desynchronises; 0: both by half the depth, so left and right hand look the same,
  yet unlike both hands, which desynchronise both hemispheres fully);
- ``rest_separability``: any imagery also attenuates the occipital alpha by this times
  ``erd_depth`` (attention to the task; in real EEG much of rest vs imagery is outside the
  motor cortex), 0: not at all;
- ``nonstationarity`` scales how much the statistics change over time. Per run (per ``seed``,
  :class:`RunConditions`): the cap shifts (:data:`CAP_SHIFT_MM`), each rhythm, the background
  and the ERD depth change in amplitude (:data:`RUN_LOG_SD`), so a classifier calibrated on
  one run meets shifted class statistics in the next; per episode (each stretch of rest or of
  one class): the rhythms wax and wane (:data:`EPISODE_LOG_SD`), so rest is as variable as in
  real EEG. 0: stationary, every run alike.

Every random source is seeded: ``seed`` drives the time series, the run's conditions and the
episodes, ``head_seed`` the head model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal

from mindgrasp_common.sos_stream import SosStream

from . import EEGError
from .montage import BOTH_FEET, BOTH_HANDS, LEFT_HAND, NAUTILUS_32, NAUTILUS_RATE, RIGHT_HAND

#: Electrode positions (mm, MNE head coordinates: x right, y nose, z up), standard 10-20.
ELECTRODE_POSITIONS_MM: dict[str, tuple[float, float, float]] = {
    'Fp1': (-29.4, 83.9, -7.0), 'Fp2': (29.9, 84.9, -7.1),
    'AF3': (-33.7, 76.8, 21.2), 'AF4': (35.7, 77.7, 22.0),
    'F7': (-70.3, 42.5, -11.4), 'F3': (-50.2, 53.1, 42.2),
    'Fz': (0.3, 58.5, 66.5), 'F4': (51.8, 54.3, 40.8),
    'F8': (73.0, 44.4, -12.0), 'FC5': (-77.2, 18.6, 24.5),
    'FC1': (-34.1, 26.0, 80.0), 'FC2': (34.8, 26.4, 78.8),
    'FC6': (79.5, 19.9, 24.4), 'T7': (-84.2, -16.0, -9.3),
    'C3': (-65.4, -11.6, 64.4), 'Cz': (0.4, -9.2, 100.2),
    'C4': (67.1, -10.9, 63.6), 'T8': (85.1, -15.0, -9.5),
    'CP5': (-79.6, -46.6, 30.9), 'CP1': (-35.5, -47.3, 91.3),
    'CP2': (38.4, -47.1, 90.7), 'CP6': (83.3, -46.1, 31.2),
    'P7': (-72.4, -73.5, -2.5), 'P3': (-53.0, -78.8, 55.9),
    'Pz': (0.3, -81.1, 82.6), 'P4': (55.7, -78.6, 56.6),
    'P8': (73.1, -73.1, -2.5), 'PO3': (-36.5, -100.9, 37.2),
    'PO4': (36.8, -100.8, 36.4), 'O1': (-29.4, -112.4, 8.8),
    'Oz': (0.1, -114.9, 14.7), 'O2': (29.8, -112.2, 8.8),
}

#: Centre of the spherical head used to place sources (mm).
_HEAD_CENTRE_MM = np.array([0.0, -15.0, 20.0])

#: Rhythmic sources: name -> (electrode above it, depth fraction towards the centre, band).
SOURCES: dict[str, tuple[str, float, str]] = {
    'alpha_occipital': ('Oz', 0.35, 'alpha'),
    'mu_left_motor': ('C3', 0.3, 'mu'),      # left hemisphere: right-hand area
    'mu_right_motor': ('C4', 0.3, 'mu'),     # right hemisphere: left-hand area
    'mu_vertex': ('Cz', 0.4, 'mu'),          # interhemispheric: foot area
    'beta_left_motor': ('C3', 0.3, 'beta'),
    'beta_right_motor': ('C4', 0.3, 'beta'),
    'beta_vertex': ('Cz', 0.4, 'beta'),
}

#: Which motor areas desynchronise for each MI class.
ERD_AREAS: dict[int, tuple[str, ...]] = {
    LEFT_HAND: ('right_motor',),
    RIGHT_HAND: ('left_motor',),
    BOTH_HANDS: ('left_motor', 'right_motor'),
    BOTH_FEET: ('vertex',),
}

_BANDS_HZ = {'alpha': (8.0, 12.0), 'mu': (9.0, 13.0), 'beta': (18.0, 26.0)}

#: the contralateral motor area of each one-hand class, and the ipsilateral one
_LATERAL: dict[int, tuple[str, str]] = {LEFT_HAND: ('right_motor', 'left_motor'),
                                        RIGHT_HAND: ('left_motor', 'right_motor')}
#: RMS cap displacement per horizontal axis (mm) between runs at ``nonstationarity`` 1
CAP_SHIFT_MM = 5.0
#: SD of the natural log of the run-to-run amplitude factors at ``nonstationarity`` 1: each
#: source rhythm (~30 %), the background (~20 %), the ERD depth (~30 %)
RUN_LOG_SD: dict[str, float] = {'source': 0.3, 'background': 0.2, 'erd': 0.3}
#: SD of the natural log of each rhythm's amplitude factor per episode (each stretch of rest or
#: of one imagined class) at ``nonstationarity`` 1: rhythms wax and wane over seconds, which
#: makes rest as variable as in real EEG (imagery, which suppresses them, less so)
EPISODE_LOG_SD = 0.3


@dataclass(frozen=True)
class RunConditions:
    """Random recording conditions of one run (``nonstationarity`` > 0).

    Attributes
    ----------
    cap_shift_mm : ndarray, shape (3,)
        Displacement of every electrode (mm, head coordinates; z stays 0).
    source_gain : ndarray, shape (n_sources,)
        Amplitude factor of each rhythmic source.
    background_gain : float
        Amplitude factor of the 1/f background.
    erd_gain : float
        Factor on the ERD depth of every class (how engaged the subject is in this run; one
        factor for all, as a factor per class would make classes differ by chance within a run).
    """

    cap_shift_mm: np.ndarray
    source_gain: np.ndarray
    background_gain: float
    erd_gain: float

    #: standard normal draws that make one run's conditions
    N_DRAWS = 2 + len(SOURCES) + 2

    @classmethod
    def draw(cls, nonstationarity: float, seed: int, head_seed: int = 0) -> RunConditions:
        """Conditions of the run ``seed``; the same draws at every ``nonstationarity``, scaled by
        it, so figures change smoothly with the setting (and 0 gives the nominal run)."""
        rng = np.random.default_rng([seed, 2, head_seed])   # [seed, 1]: the artefacts
        return cls.from_normals(nonstationarity, rng.standard_normal(cls.N_DRAWS))

    @classmethod
    def from_normals(cls, nonstationarity: float, z: np.ndarray) -> RunConditions:
        """Conditions from ``N_DRAWS`` standard normal draws ``z`` (cap x/y, each source, the
        background, the ERD depth), scaled by ``nonstationarity``."""
        z = np.asarray(z, dtype=float)
        if z.shape != (cls.N_DRAWS,):
            msg = f'run_normals must have shape ({cls.N_DRAWS},); got {z.shape}.'
            raise EEGError(msg)
        z_cap, z_src, (z_bg, z_erd) = z[:2], z[2:-2], z[-2:]
        ns = float(nonstationarity)
        return cls(cap_shift_mm=np.array([*(ns * CAP_SHIFT_MM * z_cap), 0.0]),
                   source_gain=np.exp(ns * RUN_LOG_SD['source'] * z_src),
                   background_gain=float(np.exp(ns * RUN_LOG_SD['background'] * z_bg)),
                   erd_gain=float(np.exp(ns * RUN_LOG_SD['erd'] * z_erd)))


@dataclass(frozen=True)
class HeadModel:
    """Fixed linear mixing of sources to electrodes.

    Attributes
    ----------
    channel_names : tuple of str, length n_channels
    source_names : tuple of str, length n_sources
    mixing : ndarray, shape (n_channels, n_sources)
        Gain from source amplitude to electrode potential; each column peaks at 1.
    smoothing : ndarray, shape (n_channels, n_channels)
        Spatial smoothing of the background (rows have unit norm, so the background RMS is kept).
    blink_topography, emg_left, emg_right : ndarray, shape (n_channels,)
        Artefact topographies, peak 1.
    """

    channel_names: tuple[str, ...]
    source_names: tuple[str, ...]
    mixing: np.ndarray
    smoothing: np.ndarray
    blink_topography: np.ndarray
    emg_left: np.ndarray
    emg_right: np.ndarray

    @classmethod
    def build(cls, channel_names: tuple[str, ...] = NAUTILUS_32, seed: int = 0,
              cap_shift_mm: np.ndarray | None = None) -> HeadModel:
        """Head model for ``channel_names`` (10-20 names) with a seeded 10 % gain scatter.

        ``cap_shift_mm`` (shape (3,), mm) moves every electrode by that much: the same head and
        sources (same ``seed``) seen through a cap put on differently.
        """
        unknown = [c for c in channel_names if c not in ELECTRODE_POSITIONS_MM]
        if unknown:
            msg = (f'The synthetic head model has no position for channels {unknown}; use names '
                   f'from {sorted(ELECTRODE_POSITIONS_MM)}.')
            raise EEGError(msg)
        rng = np.random.default_rng(seed)
        pos = np.array([ELECTRODE_POSITIONS_MM[c] for c in channel_names]) / 1000.0  # (n_ch, 3) m
        if cap_shift_mm is not None:
            pos = pos + np.asarray(cap_shift_mm, dtype=float) / 1000.0
        centre = _HEAD_CENTRE_MM / 1000.0
        columns = []
        for electrode, depth, _band in SOURCES.values():
            above = np.array(ELECTRODE_POSITIONS_MM[electrode]) / 1000.0
            radial = above - centre
            # a radial current dipole 'depth' of the way from the scalp to the centre, jittered 3 mm
            src = above - depth * radial + rng.normal(0.0, 0.003, 3)
            orient = radial / np.linalg.norm(radial)
            d = pos - src
            gain = d @ orient / np.linalg.norm(d, axis=1) ** 3  # infinite-medium dipole potential
            gain = gain / np.max(np.abs(gain))
            gain = gain * (1.0 + 0.1 * rng.standard_normal(len(gain)))
            columns.append(gain / np.max(np.abs(gain)))
        mixing = np.stack(columns, axis=1)
        dist = np.linalg.norm(pos[:, None, :] - pos[None, :, :], axis=2)
        kernel = np.exp(-dist / 0.035)
        smoothing = kernel / np.linalg.norm(kernel, axis=1, keepdims=True)
        eyes = np.array([0.0, 0.095, -0.035])
        blink = np.exp(-np.linalg.norm(pos - eyes, axis=1) / 0.03)
        emg_l = np.exp(-np.linalg.norm(pos - np.array(ELECTRODE_POSITIONS_MM['T7']) / 1000, axis=1)
                       / 0.025)
        emg_r = np.exp(-np.linalg.norm(pos - np.array(ELECTRODE_POSITIONS_MM['T8']) / 1000, axis=1)
                       / 0.025)
        return cls(tuple(channel_names), tuple(SOURCES), mixing, smoothing,
                   blink / blink.max(), emg_l / emg_l.max(), emg_r / emg_r.max())


def _unit_variance_sos(sos: np.ndarray) -> np.ndarray:
    """Scale a filter so white noise of unit variance comes out with unit variance."""
    _, h = signal.sosfreqz(sos, worN=8192)
    sos = sos.copy()
    sos[0, :3] /= np.sqrt(np.mean(np.abs(h) ** 2))
    return sos


class SyntheticEEG:
    """Stateful generator of continuous synthetic EEG, one chunk at a time.

    Parameters
    ----------
    channel_names : sequence of str
        10-20 names (default: the 32-channel g.Nautilus montage).
    sample_rate : float
        Sampling rate (Hz), at least 60.
    seed : int
        Seed of all time series (same seed, same samples).
    head_seed : int
        Seed of the fixed head model (keep it fixed across sessions of one virtual subject).
    background_rms, alpha_rms, mu_rms, beta_rms, sensor_noise_rms : float
        RMS amplitudes (V); rhythms at the electrode above their source.
    erd_depth : float
        Fractional amplitude drop of mu and beta during imagery (0..1; 0.5 = -75 % power).
    separability : float
        Scale on ``erd_depth`` for every class (>= 0; 1 = ``erd_depth``, 0 = no motor ERD;
        depths are capped at 1). Sets how well classes, and imagery from rest, can be told
        apart.
    lateral_separability : float
        0..1: how lateralised a one-hand ERD is. With ``x``, the contralateral hemisphere
        desynchronises by ``(1 + x) / 2`` and the ipsilateral one by ``(1 - x) / 2`` of the
        class depth: 1 = only contralateral (left vs right as easy as hands vs feet), 0 = both
        alike (left and right hand indistinguishable); the other classes are unchanged.
    rest_separability : float
        >= 0: during any imagery the occipital alpha drops by ``rest_separability *
        erd_depth`` (capped at 1): rest vs imagery gets easier, the classes stay as they are.
        0 = imagery differs from rest by the motor ERD only.
    nonstationarity : float
        >= 0: size of the changes over time: this run's recording conditions, drawn from
        ``seed`` (:class:`RunConditions`: at 1 a ~5 mm cap shift, ~30 % rhythm and ERD and
        ~20 % background amplitude changes), and the rhythms' amplitudes per episode (~30 % at
        1). 0 = stationary, every run alike.
    run_normals : ndarray, shape (RunConditions.N_DRAWS,), optional
        The run's standard normal draws instead of drawing them from ``seed`` (stratified
        sampling over many runs, as :mod:`~mindgrasp_experiments.decodability` does).
    erd_tau : float
        Time constant of ERD onset and offset (s).
    blink_rate, emg_rate : float
        Mean artefact rate (events per second); 0 disables.
    blink_amplitude, emg_rms : float
        Blink peak at Fp1/Fp2 (V); EMG burst RMS at T7/T8 (V).
    line_noise : float
        Mains interference amplitude (V), 0 disables; ``line_freq`` in Hz.
    """

    def __init__(self, channel_names: tuple[str, ...] | list[str] = NAUTILUS_32,
                 sample_rate: float = NAUTILUS_RATE, *, seed: int = 0, head_seed: int = 0,
                 background_rms: float = 10e-6, alpha_rms: float = 8e-6, mu_rms: float = 6e-6,
                 beta_rms: float = 3e-6, sensor_noise_rms: float = 0.5e-6,
                 erd_depth: float = 0.5, erd_tau: float = 0.3,
                 blink_rate: float = 0.0, blink_amplitude: float = 100e-6,
                 emg_rate: float = 0.0, emg_rms: float = 20e-6,
                 line_noise: float = 0.0, line_freq: float = 50.0,
                 separability: float = 1.0, lateral_separability: float = 1.0,
                 rest_separability: float = 0.0, nonstationarity: float = 0.0,
                 run_normals: np.ndarray | None = None) -> None:
        if sample_rate < 60.0:
            msg = (f'The synthetic EEG needs a sample rate of at least 60 Hz to carry beta '
                   f'rhythms; {sample_rate} Hz is too low, use e.g. 250 Hz.')
            raise EEGError(msg)
        if not 0.0 <= erd_depth <= 1.0:
            msg = f'erd_depth must be within 0..1 (fraction of amplitude); {erd_depth} is invalid.'
            raise EEGError(msg)
        if not (np.isfinite(separability) and separability >= 0.0):
            msg = (f'separability must be >= 0 (1 = erd_depth, 0 = no imagery signature); '
                   f'{separability} is invalid.')
            raise EEGError(msg)
        if not 0.0 <= lateral_separability <= 1.0:
            msg = (f'lateral_separability must be within 0..1 (1 = one-hand ERD only '
                   f'contralateral); {lateral_separability} is invalid.')
            raise EEGError(msg)
        if not (np.isfinite(rest_separability) and rest_separability >= 0.0):
            msg = (f'rest_separability must be >= 0 (occipital alpha drop during imagery, in '
                   f'units of erd_depth); {rest_separability} is invalid.')
            raise EEGError(msg)
        if not (np.isfinite(nonstationarity) and nonstationarity >= 0.0):
            msg = (f'nonstationarity must be >= 0 (0 = stationary, 1 = typical changes '
                   f'between sessions); {nonstationarity} is invalid.')
            raise EEGError(msg)
        self.channel_names = tuple(channel_names)
        self.sample_rate = float(sample_rate)
        self.separability, self.lateral_separability = separability, lateral_separability
        self.rest_separability, self.nonstationarity = rest_separability, nonstationarity
        # nonstationarity 0 draws nothing and changes nothing: the original output, bit for bit
        self.run: RunConditions | None = None
        if nonstationarity > 0:
            self.run = (RunConditions.draw(nonstationarity, seed, head_seed)
                        if run_normals is None
                        else RunConditions.from_normals(nonstationarity, run_normals))
        self.head = HeadModel.build(self.channel_names, head_seed,
                                    None if self.run is None else self.run.cap_shift_mm)
        self.erd_depth = erd_depth
        self.blink_rate, self.blink_amplitude = blink_rate, blink_amplitude
        self.emg_rate, self.emg_rms = emg_rate, emg_rms
        self.line_noise, self.line_freq = line_noise, line_freq
        self.background_rms, self.sensor_noise_rms = background_rms, sensor_noise_rms
        self._rng = np.random.default_rng(seed)
        n_ch, n_src = len(self.channel_names), len(SOURCES)
        fs = self.sample_rate
        # 1/f filter (Kasdin/Kellet approximation, ~3 decades), scaled to unit output variance
        b = np.array([0.049922035, -0.095993537, 0.050612699, -0.004408786])
        a = np.array([1.0, -2.494956002, 2.017265875, -0.522189400])
        self._pink = SosStream(_unit_variance_sos(signal.tf2sos(b, a)), n_ch)
        band_sos = {band: _unit_variance_sos(signal.butter(2, lohi, 'bandpass', fs=fs,
                                                           output='sos'))
                    for band, lohi in _BANDS_HZ.items()}
        self._src_bands = [band for _e, _d, band in SOURCES.values()]
        # the sources of one band go through one filter call (columns are filtered
        # independently, so this is the same signal as one call per source, for half the calls)
        self._band_cols = {band: np.array([i for i, b in enumerate(self._src_bands) if b == band])
                           for band in dict.fromkeys(self._src_bands)}
        self._band_filters = {band: SosStream(band_sos[band], len(cols))
                              for band, cols in self._band_cols.items()}
        rms = {'alpha': alpha_rms, 'mu': mu_rms, 'beta': beta_rms}
        self._src_rms = np.array([rms[b] for b in self._src_bands])
        if self.run is not None:
            self._src_rms = self._src_rms * self.run.source_gain
        self._src_area = [name.split('_', 1)[1] for name in SOURCES]
        self._gain = np.ones(n_src)                   # current (smoothed) ERD gain per source
        self._alpha_gain = float(np.exp(-1.0 / (erd_tau * fs))) if erd_tau > 0 else 0.0
        # artefacts have their own stream, drawn per event, so chunking never changes the signal
        self._art_rng = np.random.default_rng([seed, 1])
        self._next_onset = {kind: self._draw_onset(kind, 0) for kind in ('blink', 'emg')}
        self._events: list[tuple[int, np.ndarray, np.ndarray]] = []  # (onset, wave, topography)
        self.n_generated = 0                          # samples generated so far
        # rhythm amplitudes of the current episode (nonstationarity > 0): drawn when the class
        # changes, from their own stream, so chunking never changes them
        self._episode_rng = np.random.default_rng([seed, 3, head_seed])
        self._episode: object = 'none yet'
        self._episode_rhythm = np.ones(n_src)

    @property
    def n_channels(self) -> int:
        """Number of channels."""
        return len(self.channel_names)

    def erd_depths(self, mi_class: int | None) -> dict[str, float]:
        """Fractional amplitude drop (0..1) of each desynchronised motor area for a class."""
        if mi_class is None:
            return {}
        depth = self.erd_depth * self.separability
        if self.run is not None:
            depth = depth * self.run.erd_gain
        depths = dict.fromkeys(ERD_AREAS.get(mi_class, ()), depth)
        if mi_class in _LATERAL and self.lateral_separability < 1.0:
            # the one-hand ERD spreads to the other hemisphere, its sum kept: left and right
            # hand converge on each other, not on both hands (which desynchronise both fully)
            contra, ipsi = _LATERAL[mi_class]
            depths[contra] = depth * (1.0 + self.lateral_separability) / 2.0
            depths[ipsi] = depth * (1.0 - self.lateral_separability) / 2.0
        if self.rest_separability > 0.0:
            # attention to the task: any imagery also blocks the occipital alpha (in real EEG
            # much of rest vs imagery is there, not over the motor cortex)
            alpha = self.erd_depth * self.rest_separability
            depths['occipital'] = alpha * self.run.erd_gain if self.run is not None else alpha
        return {area: min(d, 1.0) for area, d in depths.items()}

    def erd_target(self, mi_class: int | None) -> np.ndarray:
        """Target amplitude gain per source, shape (n_sources,), for an imagined class or None."""
        depths = self.erd_depths(mi_class)
        return np.array([1.0 - depths[area] if area in depths else 1.0
                         for area in self._src_area])

    def generate(self, n_samples: int, mi_class: int | None = None) -> np.ndarray:
        """Generate the next ``n_samples`` samples.

        Parameters
        ----------
        n_samples : int
        mi_class : int or None
            Imagined class (0 left hand, 1 right hand, 2 both hands, 3 both feet), None = rest.

        Returns
        -------
        data : ndarray, shape (n_samples, n_channels), float64, volts
        """
        n = int(n_samples)
        if n <= 0:
            return np.zeros((0, self.n_channels))
        if mi_class is not None and mi_class not in ERD_AREAS:
            msg = f'mi_class must be 0..3 or None; {mi_class!r} is not a motor-imagery class.'
            raise EEGError(msg)
        # one draw per sample row keeps the output independent of how it is chunked
        noise = self._rng.standard_normal((n, 2 * self.n_channels + len(SOURCES)))
        white, src_white = noise[:, :self.n_channels], noise[:, self.n_channels:-self.n_channels]
        pink = self._pink(white)
        background = (self.background_rms if self.run is None
                      else self.background_rms * self.run.background_gain)
        data = background * pink @ self.head.smoothing.T
        target = self.erd_target(mi_class)
        if self.run is not None:                # this episode's rhythm amplitudes
            if mi_class != self._episode:
                self._new_episode(mi_class)
            target = target * self._episode_rhythm
        # smoothed ERD gain, sample by sample (first-order low-pass towards the target)
        decay = self._alpha_gain ** np.arange(1, n + 1)[:, None]
        gains = target + (self._gain - target) * decay          # (n, n_src)
        self._gain = gains[-1].copy()
        sources = np.empty((n, len(SOURCES)))
        for band, cols in self._band_cols.items():
            sources[:, cols] = self._band_filters[band](src_white[:, cols])
        data += (sources * gains * self._src_rms) @ self.head.mixing.T
        data += self.sensor_noise_rms * noise[:, -self.n_channels:]
        self._add_artefacts(data)
        if self.line_noise > 0:
            t = (self.n_generated + np.arange(n)) / self.sample_rate
            data += self.line_noise * np.sin(2 * np.pi * self.line_freq * t)[:, None]
        self.n_generated += n
        return data

    def _new_episode(self, mi_class: int | None) -> None:
        """Draw the rhythm amplitudes of the episode (rest or a class) that starts now."""
        self._episode = mi_class
        z = self._episode_rng.standard_normal(len(SOURCES))
        self._episode_rhythm = np.exp(self.nonstationarity * EPISODE_LOG_SD * z)

    def _draw_onset(self, kind: str, after: int) -> int:
        """Sample index of the next artefact of ``kind`` (Poisson process), or a huge number."""
        rate = self.blink_rate if kind == 'blink' else self.emg_rate
        if rate <= 0:
            return np.iinfo(np.int64).max
        return after + 1 + int(self._art_rng.exponential(self.sample_rate / rate))

    def _add_artefacts(self, data: np.ndarray) -> None:
        n, fs, start = data.shape[0], self.sample_rate, self.n_generated
        rng = self._art_rng
        for kind in ('blink', 'emg'):
            while self._next_onset[kind] < start + n:
                onset = self._next_onset[kind]
                if kind == 'blink':
                    phase = np.arange(int(0.3 * fs)) / (0.3 * fs)
                    wave = self.blink_amplitude * np.sin(np.pi * phase) ** 2
                    topo = self.head.blink_topography
                else:
                    length = int(rng.uniform(0.3, 1.0) * fs)
                    env = np.sin(np.pi * np.arange(length) / length)
                    burst = np.diff(rng.standard_normal(length + 1)) / np.sqrt(2.0)
                    wave = self.emg_rms * env * burst
                    topo = self.head.emg_right if rng.random() < 0.5 else self.head.emg_left
                self._events.append((onset, wave, topo))
                self._next_onset[kind] = self._draw_onset(kind, onset)
        keep = []
        for onset, wave, topo in self._events:
            lo, hi = max(onset, start), min(onset + len(wave), start + n)
            if hi > lo:
                data[lo - start:hi - start] += wave[lo - onset:hi - onset, None] * topo
            if onset + len(wave) > start + n:
                keep.append((onset, wave, topo))
        self._events = keep
