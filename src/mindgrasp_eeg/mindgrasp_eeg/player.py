"""The dataset player: streams recorded EEG files over LSL in real time (ROS-free).

Readers: EDF/EDF+, BDF, GDF and FIF through MNE, XDF through pyxdf. EEGMMIDB runs can be named as
``eegbci:<subject>:<run>[,<run>...]`` (e.g. ``eegbci:1:4,8``); they are found with MNE's loader
in ``$MNE_DATASETS_EEGBCI_PATH`` (or downloaded by MNE), and their channel names are standardised
(``C3..`` -> ``C3``).

Streams: an EEG outlet (values in microvolts, channel labels and units in the metadata, the file's
sample rate as nominal rate) and a ``Markers`` outlet named ``<name>-markers`` carrying each
annotation's description. Sample ``k`` of the file gets the LSL timestamp ``t0 + k / (rate * fs)``
and an annotation at onset ``o`` (s) gets ``t0 + o / rate``, so markers are aligned with samples
exactly, whatever the push jitter. With ``rate`` != 1 timestamps are compressed accordingly.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pylsl

from mindgrasp_common.types import Recording

from . import EEGError
from .lsl import EEGOutlet, MarkerOutlet, unit_scale

__all__ = ['DatasetPlayer', 'Recording', 'concatenate', 'expand_sources', 'load_recording']

MNE_SUFFIXES = {'.edf': 'edf', '.bdf': 'bdf', '.gdf': 'gdf', '.fif': 'fif', '.fif.gz': 'fif'}


def expand_sources(sources: Sequence[str]) -> list[str]:
    """Turn ``eegbci:<subject>:<runs>`` entries into file paths (others unchanged)."""
    out: list[str] = []
    for src in sources:
        if not src.startswith('eegbci:'):
            out.append(src)
            continue
        try:
            _, subject, runs = src.split(':')
            run_list = [int(r) for r in runs.split(',')]
            subj = int(subject.lstrip('Ss'))
        except ValueError as exc:
            msg = (f'{src!r} is not an EEGMMIDB reference; write eegbci:<subject>:<run>[,<run>], '
                   f'e.g. eegbci:1:4,8.')
            raise EEGError(msg) from exc
        import mne

        # MNE finds the data itself: $MNE_DATASETS_EEGBCI_PATH, else its config, else ~/mne_data
        try:
            paths = mne.datasets.eegbci.load_data(subj, run_list, update_path=False,
                                                  verbose='error')
        except Exception as exc:    # download or registry errors of MNE/pooch (S999 is unknown)
            problem = ' '.join(str(exc).split())
            msg = (f'MNE could not provide the EEGMMIDB recording {src} ({type(exc).__name__}: '
                   f'{problem}); EEGMMIDB has subjects 1-109 and runs 1-14. Set '
                   'MNE_DATASETS_EEGBCI_PATH to a folder that holds it, or allow the download.')
            raise EEGError(msg) from None
        out.extend(str(p) for p in paths)
    return out


def _suffix(path: Path) -> str:
    name = path.name.lower()
    return '.fif.gz' if name.endswith('.fif.gz') else path.suffix.lower()


def load_recording(path: str | os.PathLike) -> Recording:
    """Read one EEG file (EDF/BDF/GDF/FIF with MNE, XDF with pyxdf) into volts.

    Raises
    ------
    EEGError
        Missing, unsupported or corrupt file; the message names the file and the fix.
    """
    p = Path(path)
    if not p.is_file():
        msg = f'The EEG file {str(p)!r} does not exist; check the path.'
        raise EEGError(msg)
    suffix = _suffix(p)
    try:
        if suffix == '.xdf':
            return _load_xdf(p)
        if suffix not in MNE_SUFFIXES:
            msg = (f'The EEG file {str(p)!r} has an unsupported format {suffix!r}; use EDF, BDF, '
                   f'GDF, FIF or XDF.')
            raise EEGError(msg)
        return _load_mne(p, MNE_SUFFIXES[suffix])
    except EEGError:
        raise
    except Exception as exc:
        msg = (f'Cannot read the EEG file {str(p)!r} ({type(exc).__name__}: {exc}). The file is '
               f'probably corrupt or truncated; re-export or re-download it.')
        raise EEGError(msg) from exc


def _load_mne(path: Path, kind: str) -> Recording:
    import mne

    reader = {'edf': mne.io.read_raw_edf, 'bdf': mne.io.read_raw_bdf,
              'gdf': mne.io.read_raw_gdf, 'fif': mne.io.read_raw_fif}[kind]
    raw = reader(str(path), preload=True, verbose='error')
    if raw.ch_names and all(c.endswith('.') for c in raw.ch_names):   # EEGMMIDB spelling
        mne.datasets.eegbci.standardize(raw)
    data = raw.get_data().T                              # MNE keeps volts
    if not np.isfinite(data).any() or len(data) == 0:
        msg = f'The EEG file {str(path)!r} contains no samples; re-export it.'
        raise EEGError(msg)
    ann = [(float(a['onset'] - raw.first_time), float(a['duration']), str(a['description']))
           for a in raw.annotations]
    return Recording(data=data, rate=float(raw.info['sfreq']), channels=list(raw.ch_names),
                     annotations=ann, source=str(path))


def _load_xdf(path: Path) -> Recording:
    import pyxdf

    streams, _header = pyxdf.load_xdf(str(path), dejitter_timestamps=True)

    def srate(s: dict) -> float:
        return float(s['info']['nominal_srate'][0])

    signal = [s for s in streams if srate(s) > 0 and len(s['time_stamps'])]
    if not signal:
        msg = f'The XDF file {str(path)!r} holds no regularly sampled stream; record the EEG too.'
        raise EEGError(msg)
    eeg_like = [s for s in signal if s['info']['type'][0].lower() == 'eeg'] or signal
    eeg = max(eeg_like, key=lambda s: int(s['info']['channel_count'][0]))
    n_ch = int(eeg['info']['channel_count'][0])
    names, units = [f'ch{k + 1}' for k in range(n_ch)], ['microvolts'] * n_ch
    try:
        chans = eeg['info']['desc'][0]['channels'][0]['channel']
        names = [c['label'][0] for c in chans]
        units = [(c.get('unit') or ['microvolts'])[0] or 'microvolts' for c in chans]
    except (KeyError, IndexError, TypeError):
        pass
    scales = np.array([unit_scale(u) for u in units])
    data = np.asarray(eeg['time_series'], dtype=np.float64) * scales
    t0 = float(eeg['time_stamps'][0])
    ann = []
    for s in streams:
        if s['info']['channel_format'][0] == 'string':
            for ts, values in zip(s['time_stamps'], s['time_series'], strict=True):
                ann.append((float(ts) - t0, 0.0, str(values[0])))
    ann.sort()
    return Recording(data=data, rate=srate(eeg), channels=names, annotations=ann,
                     source=str(path))


def concatenate(recordings: Sequence[Recording]) -> Recording:
    """Play several files back to back (same channels and rate required)."""
    first = recordings[0]
    for rec in recordings[1:]:
        if rec.channels != first.channels or rec.rate != first.rate:
            msg = (f'Cannot play {rec.source!r} after {first.source!r}: channels or rate differ '
                   f'({len(rec.channels)} ch @ {rec.rate:g} Hz vs '
                   f'{len(first.channels)} ch @ {first.rate:g} Hz); play them separately.')
            raise EEGError(msg)
    data, ann, offset = [], [], 0.0
    for rec in recordings:
        data.append(rec.data)
        ann += [(o + offset, d, desc) for o, d, desc in rec.annotations]
        offset += rec.duration
    return Recording(data=np.vstack(data), rate=first.rate, channels=list(first.channels),
                     annotations=ann, source=' + '.join(r.source for r in recordings))


class DatasetPlayer:
    """Streams a :class:`Recording` over LSL, paced in real time times ``rate``.

    Parameters
    ----------
    recording : Recording
    name : str
        EEG stream name; the marker stream is ``<name>-markers``.
    rate : float
        Playback speed (1 = real time).
    loop : bool
        Start again at the end (timestamps keep increasing).
    block : int
        Samples per push.
    manufacturer, model, reference : str
        The amplifier that recorded the file, declared in the stream's ``<acquisition>``
        metadata (default: ``MIndGrasp``, ``dataset player: <file>``, none).
    """

    def __init__(self, recording: Recording, name: str, *, rate: float = 1.0, loop: bool = False,
                 source_id: str = '', block: int = 8, stream_type: str = 'EEG',
                 manufacturer: str = 'MIndGrasp', model: str = '', reference: str = '') -> None:
        if rate <= 0:
            msg = f'The playback rate must be positive (1 = real time); {rate} is invalid.'
            raise EEGError(msg)
        self.rec, self.rate, self.loop, self.block = recording, rate, loop, max(1, block)
        self.outlet = EEGOutlet(name, recording.channels, recording.rate,
                                stream_type=stream_type, source_id=source_id or name,
                                manufacturer=manufacturer, reference=reference,
                                model=model or f'dataset player: {Path(recording.source).name}')
        self.markers = MarkerOutlet(f'{name}-markers', f'{source_id or name}-markers')
        self.n_pushed = 0                 # samples pushed, over all loops
        self.n_markers = 0
        self._t0: float | None = None
        self._ann_next = 0

    @property
    def start_time(self) -> float | None:
        """LSL time (s, this host's ``local_clock()``) of the file's sample 0; None before the
        first :meth:`step`."""
        return self._t0

    @property
    def finished(self) -> bool:
        """True when a non-looping playback has pushed everything."""
        return not self.loop and self.n_pushed >= len(self.rec.data)

    def step(self) -> int:
        """Push everything due now; returns the number of samples pushed."""
        now = pylsl.local_clock()
        if self._t0 is None:
            self._t0 = now
        fs, n_total = self.rec.rate, len(self.rec.data)
        due = int((now - self._t0) * self.rate * fs) + 1
        if not self.loop:
            due = min(due, n_total)
        pushed = 0
        while self.n_pushed < due:
            k = self.n_pushed
            pos = k % n_total
            n = min(self.block, due - k, n_total - pos)
            self._push_markers(k, k + n)
            # at rate 1 LSL places a block's earlier samples back at the nominal rate from the
            # last one's stamp; at another rate each sample needs its own (LSL would space them
            # at the file's rate, not the playback's)
            if self.rate == 1.0:
                stamps = self._t0 + (k + n - 1) / fs
            else:
                stamps = self._t0 + np.arange(k, k + n) / (fs * self.rate)
            self.outlet.push_volts(self.rec.data[pos:pos + n], stamps)
            self.n_pushed += n
            pushed += n
        return pushed

    def _push_markers(self, k0: int, k1: int) -> None:
        """Markers whose onset lies in samples [k0, k1) of the (looped) playback."""
        fs, n_total = self.rec.rate, len(self.rec.data)
        ann = self.rec.annotations
        if not ann:
            return
        while True:
            loop_i, i = divmod(self._ann_next, len(ann))
            onset, _dur, desc = ann[i]
            k = loop_i * n_total + round(onset * fs)
            if k >= k1 or (not self.loop and loop_i > 0):
                return
            # pushed with the block holding its sample (k >= k0 unless the onset is < 0)
            self.markers.push(desc, self._t0 + max(k, k0) / (fs * self.rate))
            self.n_markers += 1
            self._ann_next += 1

    def run(self, duration: float = 0.0, period: float = 0.01) -> None:
        """Play until finished (or for ``duration`` s of wall time when > 0, e.g. with loop)."""
        t_end = time.monotonic() + duration if duration > 0 else float('inf')
        while not self.finished and time.monotonic() < t_end:
            self.step()
            time.sleep(period)

    def close(self) -> None:
        """Withdraw both streams."""
        self.outlet.close()
        self.markers.close()
