"""The acquisition core: LSL inlet -> validated, unit-converted, gap-aware EEG chunks (ROS-free).

How LSL time maps to ROS time
-----------------------------
Pulled LSL timestamps ``t_lsl`` (s) are in this host's ``pylsl.local_clock()`` domain after clock
synchronisation and dejitter (see :mod:`mindgrasp_eeg.lsl`); a sender on the same host shares that
clock, so clock synchronisation is skipped for it (its estimate would only add jitter). At each
pull the node reads both clocks at one moment (:func:`read_clocks`), ``lsl_now = local_clock()`` and
``ros_now`` (the node clock: system time, or ``/clock`` with ``use_sim_time``), and stamps a sample
with ::

    stamp_ros = ros_now - (lsl_now - t_lsl)

i.e. a sample keeps its age. With the system clock the offset ``ros_now - lsl_now`` is constant
(wall time minus monotonic time, up to NTP slewing), so dejittered samples get evenly spaced ROS
stamps and ``EEGChunk.header.stamp`` is the ROS time of the first sample (sample ``k`` at
``stamp + k / sample_rate``). With simulated time the offset follows the simulation clock; stamps
then place samples at the simulated time they were streamed, which is what the virtual amplifier
(paced by ``/clock``) produces. Stamps never go backwards (:func:`ros_stamp_ns` is clamped by the
caller to the previous chunk's end).

Units
-----
Values are converted to volts with the factor of the stream's channel unit (metadata
``<unit>``; ``stream_unit`` overrides it; streams that declare none are taken as microvolts, with a
warning). ``EEGChunk.unit`` is ``"V"`` and ``data`` float32 volts.

Sample index, drops, order
--------------------------
Each sample gets a running index from its timestamp: consecutive samples are ``1/sample_rate``
apart, a larger gap means ``round(gap * rate) - 1`` dropped samples (inlet buffer overflow, network
loss, a stream restart). Chunks are split at gaps so ``first_sample_index`` is exact for every
sample of a chunk. Samples whose timestamp is not after the previous one are out of order: counted
and dropped.
"""

from __future__ import annotations

import contextlib
import math
import socket
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import pylsl
from pylsl.util import LostError

from . import EEGError
from .lsl import (
    StreamDescription,
    StreamFinder,
    check_stream,
    clocksync_for,
    identity_text,
    not_found_error,
    open_inlet,
    resolve_stream,
    stream_identity,
    unit_scale,
)
from .quality import QualityMonitor

NAN_POLICIES = ('replace', 'drop', 'keep')
OK, WARN, ERROR = 0, 1, 2
#: seconds a newly opened stream has to deliver its first sample before it counts as lost
FIRST_SAMPLE_GRACE = 5.0
#: seconds a waiting poll gives the rest of a block once its first sample is in: liblsl queues a
#: pushed block sample by sample, so the first one wakes the reader before the others are there;
#: without this one block in seven went out as two chunks (benchmarks/eeg.py, load 9:
#: 720 chunks for 625 blocks, p95 push-to-publish 29 ms; with it 624 chunks, p95 8.9 ms)
BLOCK_SETTLE = 0.002


def ros_stamp_ns(t_lsl: float, lsl_now: float, ros_now_ns: int) -> int:
    """ROS time (ns) of a sample stamped ``t_lsl`` (LSL s), given both clocks read at one moment."""
    return int(ros_now_ns - round((lsl_now - t_lsl) * 1e9))


def read_clocks(ros_now_ns: Callable[[], int], tries: int = 3) -> tuple[float, int]:
    """``(lsl_now, ros_now_ns)`` read at one moment: the LSL clock on either side of the ROS
    clock, the tightest bracket of a few tries. A process preempted between two plain reads
    (a loaded machine) would shift every stamp of the chunk by the preemption."""
    best: tuple[float, float, int] | None = None
    for _ in range(tries):
        before = pylsl.local_clock()
        ros = ros_now_ns()
        after = pylsl.local_clock()
        if best is None or after - before < best[0]:
            best = (after - before, (before + after) / 2, ros)
        if after - before < 1e-4:
            break
    assert best is not None
    return best[1], best[2]


@dataclass
class Chunk:
    """Consecutive samples without gaps.

    data : ndarray, shape (n_samples, n_channels), float32, volts
    timestamps : ndarray, shape (n_samples,), LSL seconds (receiver clock)
    first_index : running index of ``data[0]`` since the first sample of the session
    """

    data: np.ndarray
    timestamps: np.ndarray
    first_index: int


@dataclass
class Status:
    """Acquisition health: level (0 OK, 1 WARN, 2 ERROR), a sentence, key/value details."""

    level: int
    message: str
    values: dict[str, str] = field(default_factory=dict)


class EEGAcquisition:
    """Pulls EEG from one LSL stream, validates, converts and checks it.

    Parameters
    ----------
    name, stream_type, source_id : str
        Stream selector (any combination; empty = not used).
    n_channels, sample_rate, channel_names :
        Expected layout; 0 / empty accepts the stream's.
    adapt : bool
        On a layout mismatch adopt the stream's layout with a warning instead of raising.
    stream_unit : str
        ``'auto'`` (from the metadata) or a unit name (``'microvolts'``, ``'V'`` ...).
    max_buflen : float
        Inlet buffer bound (s, rounded up to whole seconds by LSL).
    resolve_timeout : float
        Seconds to wait for the stream at :meth:`connect`.
    lost_timeout : float
        No samples for this long (s) means the stream is lost; reconnection starts. Right after
        (re)connecting the first sample may take up to :data:`FIRST_SAMPLE_GRACE` seconds.
    nan_policy : {'replace', 'drop', 'keep'}
        Non-finite values: replaced by the channel's last finite value, samples dropped, or kept.
    dejitter, clocksync : bool
        LSL timestamp post-processing.
    quality_window, flat_threshold, rail_threshold :
        See :class:`~mindgrasp_eeg.quality.QualityMonitor` (s, V, V).
    hostname : str
        Also match the sender's host ('' = any).

    Which sender: the first stream connected to fixes the sender (:attr:`identity`: its
    source_id, host and LSL session). After a loss only a stream of that sender is taken back (a
    restarted amplifier, with a new ``uid``); a stream of the same name from another host, source
    or session is refused, counted (``refused_streams``) and named in the status.
    """

    def __init__(self, name: str = '', stream_type: str = 'EEG', source_id: str = '', *,
                 n_channels: int = 0, sample_rate: float = 0.0,
                 channel_names: Sequence[str] = (), adapt: bool = False,
                 stream_unit: str = 'auto', max_buflen: float = 1.0,
                 resolve_timeout: float = 10.0, lost_timeout: float = 0.5,
                 nan_policy: str = 'replace', dejitter: bool = True, clocksync: bool = True,
                 quality_window: float = 1.0, flat_threshold: float = 1e-7,
                 rail_threshold: float = 0.1, hostname: str = '') -> None:
        if nan_policy not in NAN_POLICIES:
            msg = f'nan_policy must be one of {NAN_POLICIES}; {nan_policy!r} is unknown.'
            raise EEGError(msg)
        if lost_timeout <= 0 or max_buflen <= 0:
            msg = (f'lost_timeout and max_buflen must be positive (s); got {lost_timeout} and '
                   f'{max_buflen}.')
            raise EEGError(msg)
        if stream_unit != 'auto':
            unit_scale(stream_unit)
        self.selector = (name, stream_type, source_id)
        self.hostname = hostname
        self.expected = (int(n_channels), float(sample_rate), tuple(channel_names))
        self.adapt, self.stream_unit, self.max_buflen = adapt, stream_unit, max_buflen
        self.resolve_timeout, self.lost_timeout, self.nan_policy = (
            resolve_timeout, lost_timeout, nan_policy)
        self.dejitter, self.clocksync = dejitter, clocksync
        self.quality_args = {'window': quality_window, 'flat_threshold': flat_threshold,
                             'rail_threshold': rail_threshold}
        self.desc: StreamDescription | None = None
        self.scale = 1.0
        self.quality: QualityMonitor | None = None
        self.warnings: list[str] = []            # layout adoption and unit warnings, newest last
        self._inlet: pylsl.StreamInlet | None = None
        self._lock = threading.Lock()            # reconnection state (reconnect thread)
        self._data_lock = threading.Lock()       # counters and quality (poll vs status)
        self._pending: tuple[pylsl.StreamInlet, StreamDescription] | None = None
        self._reconnect_error = ''
        self._reconnect_thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._search: tuple[threading.Thread, dict[str, object]] | None = None
        self._last_ts: float | None = None       # timestamp of the last accepted sample
        self._next_index = 0                     # index the next sample would get without gaps
        self._last_data_at = 0.0                 # local_clock() when samples last arrived
        self._got_data = False                   # a sample arrived since (re)connecting
        self._last_finite: np.ndarray | None = None
        self.lost = False
        self._lost_reason = ''
        self.counters = {'samples': 0, 'dropped': 0, 'out_of_order': 0, 'nonfinite_samples': 0,
                         'nan_dropped': 0, 'reconnects': 0, 'losses': 0, 'refused_streams': 0}
        #: (source_id, host, LSL session) of the first stream connected to; None before
        self.identity: tuple[str, str, str] | None = None
        self._refused: set[str] = set()          # uids of other senders' streams, refused
        self.refusals: list[str] = []            # one sentence per refused stream, newest last

    # -- connection ----------------------------------------------------------------------------
    @property
    def connected(self) -> bool:
        """True while an inlet is open and the stream is not lost."""
        return self._inlet is not None and not self.lost

    def connect(self, timeout: float | None = None) -> StreamDescription:
        """Resolve the stream, open a bounded inlet and validate its layout.

        Raises
        ------
        EEGError
            No such stream within the timeout (the message lists the visible streams), or a
            layout mismatch with ``adapt`` false.
        """
        timeout = self.resolve_timeout if timeout is None else timeout
        info = resolve_stream(*self.selector, timeout=timeout, hostname=self.hostname)
        inlet, desc = open_inlet(info, max_buflen=self.max_buflen, dejitter=self.dejitter,
                                 clocksync=self._clocksync_for(info))
        try:
            self._adopt(desc)
        except EEGError:
            inlet.close_stream()
            raise
        self._inlet = inlet
        self._last_data_at = pylsl.local_clock()
        self._got_data = False
        return desc

    @property
    def pinned(self) -> bool:
        """True when the selector names both the stream's source_id and its host: no other
        sender on the network can stand in for the amplifier."""
        return bool(self.selector[2] and self.hostname)

    @property
    def searching(self) -> bool:
        """True between :meth:`start_search` and the stream being found (or not)."""
        return self._search is not None

    def start_search(self, timeout: float | None = None) -> None:
        """Look for the stream in a background thread (liblsl's continuous resolver, polled
        every 0.1 s), so the caller never blocks (an executor keeps serving signals, timers and
        status). :meth:`finish_search` collects the outcome."""
        timeout = self.resolve_timeout if timeout is None else timeout
        finder = StreamFinder(*self.selector, self.hostname)   # bad selectors fail here, at once
        outcome: dict[str, object] = {}

        def run() -> None:
            deadline = time.monotonic() + timeout
            try:
                while not self._stop.is_set():
                    info = finder.newest()
                    if info is not None:
                        outcome['found'] = open_inlet(info, max_buflen=self.max_buflen,
                                                      dejitter=self.dejitter,
                                                      clocksync=self._clocksync_for(info))
                        return
                    if time.monotonic() >= deadline:
                        # one last look (1 s): a stream that appears as the wait ends is taken,
                        # not listed as "visible" in the error
                        try:
                            info = resolve_stream(*self.selector, timeout=1.0,
                                                  hostname=self.hostname, list_visible=False)
                        except EEGError:
                            outcome['error'] = not_found_error(finder.pred, timeout)
                            return
                        outcome['found'] = open_inlet(info, max_buflen=self.max_buflen,
                                                      dejitter=self.dejitter,
                                                      clocksync=self._clocksync_for(info))
                        return
                    self._stop.wait(0.1)
            except EEGError as exc:
                outcome['error'] = exc
            except Exception as exc:  # reported by finish_search
                outcome['error'] = EEGError(f'Opening the LSL stream failed: '
                                            f'{type(exc).__name__}: {exc}')
            finally:
                finder.close()

        thread = threading.Thread(target=run, name='eeg-search', daemon=True)
        self._search = (thread, outcome)
        thread.start()

    def wait_search(self, timeout: float) -> bool:
        """Wait up to ``timeout`` s for the search of :meth:`start_search` to end; True when
        :meth:`finish_search` has its outcome (or no search is under way)."""
        search = self._search
        if search is None:
            return True
        search[0].join(timeout)
        return not search[0].is_alive()

    def finish_search(self) -> StreamDescription | None:
        """The stream's description once the search of :meth:`start_search` found it (and its
        layout was checked), None while it goes on.

        Raises
        ------
        EEGError
            Nothing found within the timeout (visible streams listed), or a layout mismatch.
        """
        if self._search is None:
            return self.desc
        thread, outcome = self._search
        if thread.is_alive():
            return None
        self._search = None
        if 'error' in outcome:
            raise outcome['error']
        inlet, desc = outcome['found']
        try:
            self._adopt(desc)
        except EEGError:
            inlet.close_stream()
            raise
        self._inlet = inlet
        self._last_data_at = pylsl.local_clock()
        self._got_data = False
        return desc

    def _clocksync_for(self, info: pylsl.StreamInfo) -> bool:
        return clocksync_for(info, self.clocksync)

    def _adopt(self, desc: StreamDescription) -> None:
        n_ch, rate, names = self.expected
        if self.desc is not None:             # a reconnection must match what we publish
            n_ch, rate, names = (self.desc.n_channels, self.desc.sample_rate,
                                 self.desc.channel_names)
        self.warnings += check_stream(desc, n_channels=n_ch, sample_rate=rate,
                                      channel_names=names, adapt=self.adapt)
        unit = desc.unit if self.stream_unit == 'auto' else self.stream_unit
        if not unit:
            unit = 'microvolts'
            self.warnings.append(f"The LSL stream '{desc.name}' declares no channel unit; "
                                 'assuming microvolts. Set stream_unit if that is wrong.')
        self.scale = unit_scale(unit)
        if self.identity is None:
            self.identity = desc.identity     # the sender, kept for every reconnection
        elif desc.identity != self.identity:
            msg = (f"The LSL stream '{desc.name}' comes from {identity_text(desc.identity)}, "
                   f'not from {identity_text(self.identity)}, which this node connected to '
                   'first; restart the node to change amplifiers.')
            raise EEGError(msg)
        if self.desc is None or self.desc.n_channels != desc.n_channels or \
                self.desc.sample_rate != desc.sample_rate:
            self.quality = QualityMonitor(desc.channel_names, desc.sample_rate,
                                          **self.quality_args)
            self._last_finite = np.zeros(desc.n_channels)
        self.desc = desc

    def close(self) -> None:
        """Stop searching and reconnecting and close the inlet. The threads end by themselves
        within 0.1 s (their poll period; opening an inlet may take longer); waiting for them
        here would only delay a node's stop, so they get 0.1 s (they are daemon threads)."""
        self._stop.set()
        for thread in (self._reconnect_thread, self._search and self._search[0]):
            if thread is not None:
                thread.join(timeout=0.1)
        if self._inlet is not None:
            self._inlet.close_stream()
            self._inlet = None

    def _start_reconnect(self, lost_uid: str, closed: bool = False) -> None:
        if self._reconnect_thread is not None and self._reconnect_thread.is_alive():
            return

        finder = StreamFinder(*self.selector, self.hostname)

        def run() -> None:
            try:
                reconnect()
            finally:
                finder.close()

        def reconnect() -> None:
            while not self._stop.is_set():
                try:
                    # a closed outlet never sends again, but the resolver may still list it for
                    # a while: a new stream (a restarted amplifier) has a new uid
                    info = self._same_sender(finder.found(
                        exclude_uids=(lost_uid,) if closed else ()))
                    if info is None:
                        self._stop.wait(0.1)
                        continue
                    if info.uid() == lost_uid and pylsl.local_clock() - self._last_data_at < 2.0:
                        # the lost outlet may still be listed for a moment; give it time
                        self._stop.wait(0.1)
                        continue
                    inlet, desc = open_inlet(info, max_buflen=self.max_buflen,
                                             dejitter=self.dejitter,
                                             clocksync=self._clocksync_for(info))
                except EEGError as exc:
                    with self._lock:
                        self._reconnect_error = str(exc).split(' Visible streams')[0]
                    self._stop.wait(0.1)
                    continue
                except Exception as exc:  # keep trying, report it
                    with self._lock:
                        self._reconnect_error = f'{type(exc).__name__}: {exc}'
                    self._stop.wait(0.5)
                    continue
                with self._lock:
                    self._pending = (inlet, desc)
                return

        self._reconnect_thread = threading.Thread(target=run, name='eeg-reconnect', daemon=True)
        self._reconnect_thread.start()

    def _same_sender(self, found: list[pylsl.StreamInfo]) -> pylsl.StreamInfo | None:
        """The newest of ``found`` sent by the amplifier this node connected to first (same
        source_id, host and LSL session: :attr:`StreamDescription.identity`); the others are
        refused, counted once each, and named in the status (a stream of the same name from
        another rig or another run must never stand in for this one)."""
        ours = [i for i in found if self.identity is None or stream_identity(i) == self.identity]
        kept = {i.uid() for i in ours}
        for info in found:
            if info.uid() in kept or info.uid() in self._refused:
                continue
            self._refused.add(info.uid())
            self.counters['refused_streams'] += 1
            assert self.identity is not None
            with self._lock:
                self.refusals.append(
                    f"refused the LSL stream '{info.name()}' from "
                    f'{identity_text(stream_identity(info))}: not the sender this node connected '
                    f'to first ({identity_text(self.identity)}); restart the node to change '
                    'amplifiers')
                self._reconnect_error = (
                    f"refused the LSL stream '{info.name()}' from "
                    f'{identity_text(stream_identity(info))}: this node connected to '
                    f'{identity_text(self.identity)} first and accepts only that sender; '
                    'restart the node to change amplifiers')
        return max(ours, key=lambda i: i.created_at()) if ours else None

    def _mark_lost(self, closed: bool = False) -> None:
        """The stream is lost; ``closed``: its sender closed the connection (its outlet is
        gone, not just quiet), so only another stream can take its place."""
        if not self.lost:
            self.lost = True
            self.counters['losses'] += 1
        if self._inlet is not None:
            with contextlib.suppress(Exception):   # closing a dead inlet may fail
                self._inlet.close_stream()
            self._inlet = None
        self._start_reconnect(self.desc.uid if self.desc else '', closed)

    def _take_pending(self) -> None:
        with self._lock:
            pending, self._pending = self._pending, None
        if pending is None:
            return
        inlet, desc = pending
        try:
            self._adopt(desc)
        except EEGError as exc:
            inlet.close_stream()
            with self._lock:
                self._reconnect_error = str(exc)
            self._start_reconnect(desc.uid)
            return
        self._inlet = inlet
        self.lost = False
        self._reconnect_error = ''
        self.counters['reconnects'] += 1
        self._last_data_at = pylsl.local_clock()
        self._got_data = False

    # -- data ----------------------------------------------------------------------------------
    def poll(self, timeout: float = 0.0) -> list[Chunk]:
        """Pull whatever arrived; return gap-free chunks (possibly none).

        ``timeout`` (s): 0 never blocks; > 0 waits up to that long for the first sample and
        returns as soon as it arrives, with the rest of its block (:data:`BLOCK_SETTLE`, 2 ms;
        LSL's ``pull_chunk`` with a timeout would wait for ``max_samples`` instead). Waiting is
        how a reader thread publishes each block at once instead of at its next timer pull.
        One caller thread at a time: it owns the inlet (:meth:`close` waits for no pull).

        Also detects a lost stream (no samples for ``lost_timeout``) and swaps in a reconnected
        one.
        """
        if self._inlet is None:
            if self.desc is not None:
                self._take_pending()
            if self._inlet is None:
                self._stop.wait(timeout)      # a waiting caller must not spin while lost
                return []
        try:
            first, t_first = (self._inlet.pull_sample(timeout=timeout) if timeout > 0
                              else (None, None))
            # with a first sample: up to BLOCK_SETTLE s for the rest of its block (LSL's
            # pull_chunk waits until max_samples or the timeout, whichever comes first)
            raw, ts = self._inlet.pull_chunk(timeout=BLOCK_SETTLE if first is not None else 0.0,
                                             max_samples=4096, as_numpy=True)
        except LostError:
            self._lost_reason = 'the sender closed the connection'
            self._mark_lost(closed=True)
            return []
        if first is not None:
            raw = np.vstack([np.asarray(first, dtype=np.float64)[None, :],
                             np.asarray(raw, dtype=np.float64).reshape(-1, len(first))])
            ts = np.concatenate([[t_first], np.asarray(ts, dtype=np.float64)])
        now = pylsl.local_clock()
        if len(ts) == 0:
            # a freshly opened stream gets FIRST_SAMPLE_GRACE to send its first sample (an
            # amplifier app may create its outlet well before it starts streaming)
            limit = self.lost_timeout if self._got_data else max(self.lost_timeout,
                                                                  FIRST_SAMPLE_GRACE)
            if now - self._last_data_at > limit:
                self._lost_reason = f'no samples for more than {limit:g} s'
                self._mark_lost()
            return []
        self._last_data_at = now
        self._got_data = True
        with self._data_lock:                 # status() reads the counters and the quality
            return self._process(np.asarray(raw, dtype=np.float64) * self.scale,
                                 np.asarray(ts, dtype=np.float64))

    def _process(self, data: np.ndarray, ts: np.ndarray) -> list[Chunk]:
        assert self.desc is not None and self.quality is not None
        fs = self.desc.sample_rate
        # order: keep samples strictly after the running maximum
        prev = -math.inf if self._last_ts is None else self._last_ts
        running = np.maximum.accumulate(np.concatenate([[prev], ts]))[:-1]
        in_order = ts > running
        self.counters['out_of_order'] += int((~in_order).sum())
        data, ts = data[in_order], ts[in_order]
        if not len(ts):
            return []
        # running index from timestamps: steps of 1 unless samples are missing
        steps = np.ones(len(ts), dtype=np.int64)
        dts = np.diff(np.concatenate([[prev], ts]))
        gap = dts > 1.5 / fs
        if self._last_ts is None:
            gap[0] = False
        steps[gap] = np.maximum(1, np.round(dts[gap] * fs).astype(np.int64))
        self.counters['dropped'] += int((steps - 1).sum())
        index = self._next_index - 1 + np.cumsum(steps)
        self._next_index = int(index[-1]) + 1
        self._last_ts = float(ts[-1])
        self.counters['samples'] += len(ts)
        # quality and non-finite values
        self.quality.update(data)
        bad = ~np.isfinite(data)
        keep = np.ones(len(ts), dtype=bool)
        if bad.any():
            self.counters['nonfinite_samples'] += int(bad.any(axis=1).sum())
            if self.nan_policy == 'replace':
                for row in range(len(data)):
                    data[row] = np.where(bad[row], self._last_finite, data[row])
                    self._last_finite = data[row]
            elif self.nan_policy == 'drop':
                keep = ~bad.any(axis=1)
                self.counters['nan_dropped'] += int((~keep).sum())
        finite_rows = np.flatnonzero(~bad.any(axis=1))
        if len(finite_rows):
            self._last_finite = data[finite_rows[-1]].copy()
        data, ts, index = data[keep], ts[keep], index[keep]
        # split where the index jumps
        cuts = np.flatnonzero(np.diff(index) != 1) + 1
        return [Chunk(d.astype(np.float32), t, int(i[0]))
                for d, t, i in zip(np.split(data, cuts), np.split(ts, cuts),
                                   np.split(index, cuts), strict=True) if len(i)]

    # -- status --------------------------------------------------------------------------------
    def status(self) -> Status:
        """Current health, for ``/eeg/status``."""
        with self._data_lock:                 # a reader thread may be processing samples
            return self._status()

    def _status(self) -> Status:
        values = {k: str(v) for k, v in self.counters.items()}
        desc = self.desc
        if desc is not None:
            values.update(stream=desc.name, source_id=desc.source_id, hostname=desc.hostname,
                          session_id=desc.session_id, uid=desc.uid,
                          n_channels=str(desc.n_channels), sample_rate=f'{desc.sample_rate:g}',
                          unit_scale_to_volts=f'{self.scale:g}')
        if self._inlet is not None and self.clocksync and desc is not None and \
                desc.hostname != socket.gethostname():
            with contextlib.suppress(Exception):   # not estimated yet
                values['lsl_clock_offset_ms'] = f'{self._inlet.time_correction(0.0) * 1e3:.3f}'
        if desc is None:
            return Status(ERROR, 'Not connected to an LSL EEG stream yet.', values)
        if self.lost:
            since = pylsl.local_clock() - self._last_data_at
            with self._lock:
                err = self._reconnect_error
            msg = (f"The LSL stream '{desc.name}' is lost ({self._lost_reason}; last sample "
                   f'{since:.2f} s ago); waiting for it (or a new stream matching the selector) '
                   f'to come back. Check the amplifier and its LSL app.')
            if err:
                msg += f' Last reconnection problem: {err}'
            return Status(ERROR, msg, values)
        q = self.quality
        assert q is not None
        problems = []
        for label, chans in (('NaN/inf', q.nonfinite_channels()), ('flat', q.flat_channels()),
                             ('railed', q.railed_channels())):
            values[f'{label.lower().replace("/", "_")}_channels'] = ','.join(chans)
            if chans:
                problems.append(f'{label} on {", ".join(chans)}')
        if problems:
            return Status(WARN, 'Bad channels: ' + '; '.join(problems) + '. Check the electrodes '
                          '(impedance, contact) or exclude these channels.', values)
        return Status(OK, f"Streaming '{desc.name}': {desc.n_channels} channels at "
                      f'{desc.sample_rate:g} Hz.', values)
