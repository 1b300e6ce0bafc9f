"""Thin wrappers around pylsl: the amplifier side (outlets) and the acquisition side (resolve,
inlet, stream description, validation).

Units: LSL carries numbers without a mandatory unit. Outlets made here declare the unit of each
channel in the stream description (``<channels><channel><unit>microvolts</unit>``), as g.tec's and
most other amplifiers' LSL apps do; :func:`unit_scale` turns that unit into the factor to volts.
What other LSL tools write (all accepted):

- BrainVision LSL Connector, g.tec, LabRecorder/XDF files: a unit name (``microvolts``; the XDF
  meta-data convention of the LSL project names SI units in full);
- MNE-LSL (``PlayerLSL``, ``StreamInfo.set_channel_units``): the power-of-ten exponent of volts as
  an integer string, ``"0"`` volts, ``"-6"`` microvolts (MNE's FIFF unit multiplier);
- abbreviations ``V``, ``mV``, ``uV``/``µV``, ``nV``;
- OpenBCI GUI and BrainFlow's streamers declare no unit and send microvolts: an empty unit is
  taken as microvolts with a warning (``stream_unit`` overrides it).

Time: LSL timestamps are seconds of ``pylsl.local_clock()`` (a monotonic clock, CLOCK_MONOTONIC on
Linux) of the sending host. An inlet opened with :data:`PROC_FLAGS` adds the estimated offset
between the sender's and the receiver's clocks (clock synchronisation) and smooths the timestamps
with a linear regression over sample index (dejitter), so pulled timestamps are in the receiver's
``local_clock()`` domain. See :mod:`mindgrasp_eeg.acquisition` for the mapping to ROS time.
"""

from __future__ import annotations

import math
import re
import socket
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pylsl
from pylsl.util import TimeoutError as LSLTimeoutError

from . import EEGError

#: factor from a unit name (as found in LSL metadata) to volts
UNIT_SCALES: dict[str, float] = {
    'v': 1.0, 'volt': 1.0, 'volts': 1.0,
    'mv': 1e-3, 'millivolt': 1e-3, 'millivolts': 1e-3,
    'uv': 1e-6, 'µv': 1e-6, 'μv': 1e-6, 'microvolt': 1e-6, 'microvolts': 1e-6,
    'nv': 1e-9, 'nanovolt': 1e-9, 'nanovolts': 1e-9,
}

#: post-processing of pulled timestamps: clock synchronisation and dejitter (no monotonize,
#: so out-of-order samples stay visible to the counters)
PROC_FLAGS = pylsl.proc_clocksync | pylsl.proc_dejitter


def unit_scale(unit: str) -> float:
    """Factor that converts values in ``unit`` (e.g. ``'microvolts'``, ``'uV'``, or MNE-LSL's
    power-of-ten exponent of volts ``'-6'``) to volts."""
    key = unit.strip().lower()
    if re.fullmatch(r'[+-]?\d{1,2}', key) and -12 <= int(key) <= 3:
        return 10.0 ** int(key)           # MNE-LSL: "0" volts, "-3" millivolts, "-6" microvolts
    if key not in UNIT_SCALES:
        msg = (f'The EEG unit {unit!r} is unknown; use one of volts, millivolts, microvolts, '
               f'nanovolts (or V, mV, uV, nV, or a power of ten of volts such as -6, as MNE-LSL '
               f'writes), or set the stream_unit parameter.')
        raise EEGError(msg)
    return UNIT_SCALES[key]


@dataclass(frozen=True)
class StreamDescription:
    """What an LSL stream says about itself.

    ``unit`` is the channels' common unit from the metadata, empty when the stream declares none.
    The amplifier's own description, after the XDF/LSL meta-data conventions (empty when the
    stream declares none): ``manufacturer``, ``model`` and ``reference`` from
    ``<desc><acquisition>`` (the reference also from ``<desc><reference><label>``), and each
    channel's ``<unit>`` and ``<type>`` (``channel_units``, ``channel_types``: one per channel,
    or empty when the labels are missing).
    """

    name: str
    type: str
    source_id: str
    n_channels: int
    sample_rate: float
    channel_names: tuple[str, ...]
    unit: str
    channel_format: int
    hostname: str
    uid: str
    created_at: float
    manufacturer: str = ''
    model: str = ''
    reference: str = ''
    channel_units: tuple[str, ...] = ()
    channel_types: tuple[str, ...] = ()
    session_id: str = ''

    @property
    def identity(self) -> tuple[str, str, str]:
        """``(source_id, hostname, session_id)``: who sends the stream. A restarted amplifier
        keeps it (its new outlet has a new ``uid``); another amplifier of the same name, on
        another host or with another source id, does not."""
        return (self.source_id, self.hostname, self.session_id)

    @classmethod
    def from_info(cls, info: pylsl.StreamInfo) -> StreamDescription:
        """Read a (full, i.e. from ``inlet.info()``) StreamInfo; missing labels become ``ch<k>``."""
        names, units, types = [], [], []
        ch = info.desc().child('channels').child('channel')
        while not ch.empty() and len(names) < info.channel_count():
            names.append(ch.child_value('label'))
            units.append(ch.child_value('unit'))
            types.append(ch.child_value('type'))
            ch = ch.next_sibling('channel')
        if len(names) != info.channel_count():
            names = [f'ch{k + 1}' for k in range(info.channel_count())]
            units, types = [], []
        common = set(units) - {''}
        acq = info.desc().child('acquisition')
        reference = acq.child_value('reference')
        if not reference:          # the XDF EEG convention: <reference><label>..</label>
            ref = info.desc().child('reference').child('label')
            labels = []
            while not ref.empty():
                labels.append(ref.child_value())
                ref = ref.next_sibling('label')
            reference = ', '.join(label for label in labels if label)
        return cls(info.name(), info.type(), info.source_id(), info.channel_count(),
                   float(info.nominal_srate()), tuple(names),
                   common.pop() if len(common) == 1 else '', info.channel_format(),
                   info.hostname(), info.uid(), info.created_at(),
                   manufacturer=acq.child_value('manufacturer'), model=acq.child_value('model'),
                   reference=reference, channel_units=tuple(units), channel_types=tuple(types),
                   session_id=info.session_id())

    def summary(self) -> str:
        """One line: ``'name' (type, n ch @ rate Hz, source_id, host)``."""
        return (f"'{self.name}' (type {self.type!r}, {self.n_channels} ch @ "
                f"{self.sample_rate:g} Hz, source_id {self.source_id!r}, host {self.hostname!r})")


def stream_identity(info: pylsl.StreamInfo) -> tuple[str, str, str]:
    """``(source_id, hostname, session_id)`` of a resolved stream (see
    :attr:`StreamDescription.identity`)."""
    return (info.source_id(), info.hostname(), info.session_id())


def identity_text(identity: Sequence[str]) -> str:
    """``source_id 'x', host 'y', session 'z'`` for messages."""
    source_id, hostname, session_id = identity
    return f'source_id {source_id!r}, host {hostname!r}, session {session_id!r}'


def stream_predicate(name: str, stream_type: str, source_id: str, hostname: str = '') -> str:
    """An LSL (XPath 1.0) predicate over the stream's fields; quotes in values are refused."""
    fields = (('name', name), ('type', stream_type), ('source_id', source_id),
              ('hostname', hostname))
    for key, value in fields:
        if "'" in value or '"' in value:
            msg = f'The LSL stream {key} {value!r} contains a quote; LSL selectors cannot match it.'
            raise EEGError(msg)
    return ' and '.join(f"{key}='{value}'" for key, value in fields if value)


def not_found_error(pred: str, timeout: float, list_visible: bool = True) -> EEGError:
    """The error for "no stream matched ``pred`` within ``timeout`` s", listing what is visible
    (looked up for one more second) unless ``list_visible`` is false."""
    seen = visible_streams(1.0) if list_visible else []
    listing = '; '.join(s.summary() for s in seen) or 'none'
    return EEGError(f'No LSL stream with {pred} was found within {timeout:g} s. Visible streams: '
                    f'{listing}. Start the amplifier (or `mindgrasp eeg virtual-amp`) or select '
                    f'one of the visible streams by name, type or source_id.')


def visible_streams(wait_time: float = 1.0) -> list[StreamDescription]:
    """All LSL streams visible from this host (short description, no channel labels)."""
    return [StreamDescription.from_info(i) for i in pylsl.resolve_streams(wait_time=wait_time)]


def resolve_stream(name: str = '', stream_type: str = '', source_id: str = '',
                   timeout: float = 10.0, exclude_uids: Sequence[str] = (),
                   list_visible: bool = True, hostname: str = '') -> pylsl.StreamInfo:
    """Find one LSL stream by name, type, source_id and/or hostname (the newest if several
    match).

    Raises
    ------
    EEGError
        Nothing matched within ``timeout`` seconds; the message lists the visible streams
        (looked up for one more second) unless ``list_visible`` is false.
    """
    pred = stream_predicate(name, stream_type, source_id, hostname)
    if not pred:
        msg = ('No LSL stream selector given: set at least one of eeg_stream (name), '
               'stream_type or source_id.')
        raise EEGError(msg)
    found = [i for i in pylsl.resolve_bypred(pred, minimum=1, timeout=timeout)
             if i.uid() not in exclude_uids]
    if not found:
        raise not_found_error(pred, timeout, list_visible)
    return max(found, key=lambda i: i.created_at())


class StreamFinder:
    """Streams matching a selector, found in the background by liblsl's continuous resolver.

    :meth:`newest` never blocks, and a slow answer is not lost: a search in short one-shot
    resolves restarted its query every slice, and on a loaded machine (or with the discovery
    on this host only, where answers take 0.5-1 s) no slice lasted long enough to get one.
    """

    def __init__(self, name: str = '', stream_type: str = '', source_id: str = '',
                 hostname: str = '') -> None:
        self.pred = stream_predicate(name, stream_type, source_id, hostname)
        if not self.pred:
            msg = ('No LSL stream selector given: set at least one of eeg_stream (name), '
                   'stream_type or source_id.')
            raise EEGError(msg)
        self._resolver = pylsl.ContinuousResolver(pred=self.pred, forget_after=2.0)

    def newest(self, exclude_uids: Sequence[str] = ()) -> pylsl.StreamInfo | None:
        """The most recently created matching stream seen so far, or None."""
        found = self.found(exclude_uids)
        return max(found, key=lambda i: i.created_at()) if found else None

    def found(self, exclude_uids: Sequence[str] = ()) -> list[pylsl.StreamInfo]:
        """Every matching stream seen so far (but those of ``exclude_uids``)."""
        return [i for i in self._resolver.results() if i.uid() not in exclude_uids]

    def close(self) -> None:
        """Stop the background search."""
        self._resolver = None


def clocksync_for(info: pylsl.StreamInfo, clocksync: bool = True) -> bool:
    """Whether an inlet of ``info`` should apply LSL's clock offset (``time_correction``): a
    sender on this host shares our ``local_clock()``, so its offset is exactly 0 and skipping the
    estimate avoids its jumps (RTT/2 errors) on a loaded machine."""
    return clocksync and info.hostname() != socket.gethostname()


def open_inlet(info: pylsl.StreamInfo, *, max_buflen: float = 1.0, dejitter: bool = True,
               clocksync: bool = True, timeout: float = 5.0) -> tuple[pylsl.StreamInlet,
                                                                      StreamDescription]:
    """Open an inlet with a bounded buffer and the full stream description.

    ``max_buflen`` (s) bounds what LSL keeps for us: after a stall we get at most that much
    backlog, never minutes of stale data. LSL's own recovery is off; the caller re-resolves.
    """
    flags = (pylsl.proc_clocksync if clocksync else 0) | (pylsl.proc_dejitter if dejitter else 0)
    inlet = pylsl.StreamInlet(info, max_buflen=max(1, math.ceil(max_buflen)), recover=False,
                              processing_flags=flags)
    try:
        full = inlet.info(timeout=timeout)
        inlet.open_stream(timeout=timeout)
    except LSLTimeoutError as exc:
        msg = (f"The LSL stream '{info.name()}' did not answer within {timeout:g} s; check that "
               f'the sender is running and reachable (network, firewall).')
        raise EEGError(msg) from exc
    return inlet, StreamDescription.from_info(full)


def _short(names: Sequence[str], n: int = 8) -> str:
    """``[a, b, ... (k more)]`` for long channel lists in messages."""
    names = list(names)
    more = f', ... ({len(names) - n} more)' if len(names) > n else ''
    return '[' + ', '.join(names[:n]) + more + ']'


def check_stream(desc: StreamDescription, *, n_channels: int = 0, sample_rate: float = 0.0,
                 channel_names: Sequence[str] = (), adapt: bool = False) -> list[str]:
    """Compare a stream with the expected layout (0 / empty = accept anything).

    Returns the warnings when ``adapt`` is true (the stream's layout is adopted).

    Raises
    ------
    EEGError
        On a mismatch when ``adapt`` is false; the message names the stream's and the expected
        values and how to fix it.
    """
    problems = []
    if desc.channel_format not in (pylsl.cf_float32, pylsl.cf_double64, pylsl.cf_int32,
                                   pylsl.cf_int16):
        msg = (f"The LSL stream '{desc.name}' has a non-numeric channel format "
               f'({desc.channel_format}); select an EEG stream, not a marker stream.')
        raise EEGError(msg)
    if desc.sample_rate <= 0:
        msg = (f"The LSL stream '{desc.name}' has an irregular sampling rate; EEG needs a nominal "
               f'rate: select the EEG stream, not a marker stream.')
        raise EEGError(msg)
    if n_channels and desc.n_channels != n_channels:
        problems.append(f'has {desc.n_channels} channels, expected {n_channels} (n_channels)')
    if sample_rate and abs(desc.sample_rate - sample_rate) > 1e-6 * sample_rate:
        problems.append(f'runs at {desc.sample_rate:g} Hz, expected {sample_rate:g} Hz '
                        f'(sample_rate)')
    if channel_names and tuple(channel_names) != desc.channel_names:
        problems.append(f'has channels {_short(desc.channel_names)}, expected '
                        f'{_short(channel_names)} (channel_names)')
    if not problems:
        return []
    text = f"The LSL stream '{desc.name}' " + '; it '.join(problems)
    if not adapt:
        raise EEGError(text + '. Fix the parameters (or set adapt_to_stream:=true to adopt the '
                       "stream's layout), or select the right stream.")
    return [text + "; adopting the stream's layout (adapt_to_stream is true)."]


class EEGOutlet:
    """An LSL EEG outlet, as an amplifier app would create it.

    Parameters
    ----------
    name : str
        Stream name (make it unique per host; LSL streams are visible host-wide).
    channel_names : sequence of str
    sample_rate : float
        Nominal rate (Hz).
    source_id : str
        Stable id so receivers can recognise a restarted amplifier; default ``name``.
    unit : str
        Unit of the pushed values declared in the metadata (``'microvolts'`` by default, as most
        amplifier apps); :meth:`push_volts` converts from volts.
    manufacturer, model, reference : str
        The amplifier's description (``<desc><acquisition>``); an empty reference is left out.
    """

    def __init__(self, name: str, channel_names: Sequence[str], sample_rate: float, *,
                 stream_type: str = 'EEG', source_id: str = '', unit: str = 'microvolts',
                 manufacturer: str = 'MIndGrasp', model: str = 'virtual amplifier',
                 reference: str = '', chunk_size: int = 0) -> None:
        self.scale = unit_scale(unit)
        self.n_channels = len(channel_names)
        info = pylsl.StreamInfo(name, stream_type, self.n_channels, float(sample_rate),
                                pylsl.cf_float32, source_id or name)
        chans = info.desc().append_child('channels')
        for label in channel_names:
            ch = chans.append_child('channel')
            ch.append_child_value('label', label)
            ch.append_child_value('unit', unit)
            ch.append_child_value('type', 'EEG')
        acq = info.desc().append_child('acquisition')
        acq.append_child_value('manufacturer', manufacturer)
        acq.append_child_value('model', model)
        if reference:
            acq.append_child_value('reference', reference)
        self.info = info
        self._outlet = pylsl.StreamOutlet(info, chunk_size=chunk_size, max_buffered=30)

    def push_volts(self, data: np.ndarray, timestamp: float | np.ndarray = 0.0) -> None:
        """Push samples given in volts, shape (n_samples, n_channels).

        ``timestamp`` (LSL s): a float is that of the LAST sample (0: now), earlier samples are
        placed back at the nominal rate, as LSL does; an array, shape (n_samples,), gives each
        sample's own (a playback faster than the nominal rate).
        """
        data = np.asarray(data)
        if data.ndim != 2 or data.shape[1] != self.n_channels:
            msg = (f'push_volts expects an array of shape (n_samples, {self.n_channels}); got '
                   f'{data.shape}.')
            raise EEGError(msg)
        if len(data):
            stamps = timestamp if np.isscalar(timestamp) else [float(t) for t in timestamp]
            self._outlet.push_chunk(np.ascontiguousarray(data / self.scale, dtype=np.float32),
                                    stamps)

    def have_consumers(self) -> bool:
        """True when at least one inlet is connected."""
        return self._outlet.have_consumers()

    def close(self) -> None:
        """Withdraw the stream."""
        del self._outlet


class MarkerOutlet:
    """An LSL string marker stream (type ``Markers``, irregular rate), one string per event."""

    def __init__(self, name: str, source_id: str = '') -> None:
        info = pylsl.StreamInfo(name, 'Markers', 1, pylsl.IRREGULAR_RATE, pylsl.cf_string,
                                source_id or name)
        self._outlet = pylsl.StreamOutlet(info)

    def push(self, marker: str, timestamp: float = 0.0) -> None:
        """Push one marker at ``timestamp`` (LSL s; 0 = now)."""
        self._outlet.push_sample([marker], timestamp)

    def have_consumers(self) -> bool:
        """True when at least one inlet is connected."""
        return self._outlet.have_consumers()

    def close(self) -> None:
        """Withdraw the stream."""
        del self._outlet
