"""The amplifier's (or a stimulus PC's) LSL marker stream, pulled beside the EEG (ROS-free).

    inlet = MarkerInlet('MyAmp-markers')
    markers, news = inlet.poll()      # [Marker('T1', 1234.567)], [('info', 'Relaying ...')]

Amplifier apps and lab software send their triggers as an LSL stream of type ``Markers`` (one
string channel, irregular rate); ``mindgrasp eeg play`` names its own ``<eeg name>-markers``
(:func:`marker_stream_name`). The stream is looked for, and opened, in a background thread, so
:meth:`MarkerInlet.poll` never blocks. Its timestamps are moved onto this host's
``pylsl.local_clock()`` as the EEG's are: LSL's clock offset (``time_correction``) is applied for
a sender on another host (:func:`~mindgrasp_eeg.lsl.clocksync_for`); no dejitter (the rate is
irregular). A lost stream (its sender closed it) is reported once, and the search starts again
for a new stream of that name; nothing raises after the start.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import pylsl
from pylsl.util import LostError

from . import EEGError
from .lsl import StreamDescription, StreamFinder, clocksync_for, open_inlet

__all__ = ['MARKER_STREAM_OFF', 'Marker', 'MarkerInlet', 'marker_stream_name']

#: ``marker_stream`` values that mean "no marker stream"
MARKER_STREAM_OFF = ('', 'none')


def marker_stream_name(option: str, eeg_stream: str) -> str | None:
    """The marker stream's LSL name for the ``marker_stream`` option: ``none`` -> None,
    ``auto`` -> ``<eeg_stream>-markers`` (as ``mindgrasp eeg play`` names it), else ``option``."""
    option = option.strip()
    if option.lower() in MARKER_STREAM_OFF:
        return None
    return f'{eeg_stream}-markers' if option.lower() == 'auto' else option


@dataclass(frozen=True)
class Marker:
    """One marker: its string and its LSL time (s, this host's ``local_clock()``)."""

    text: str
    timestamp: float


class MarkerInlet:
    """Finds the marker stream ``name`` (type ``Markers``) and pulls its markers.

    Parameters
    ----------
    name : str
        LSL name of the marker stream.
    clocksync : bool
        Apply LSL's clock offset for a sender on another host (as the EEG inlet does).
    resolve_timeout : float
        Seconds after which a stream not found yet is reported (once); the search goes on.
    """

    def __init__(self, name: str, *, clocksync: bool = True, resolve_timeout: float = 30.0) -> None:
        self.name = name
        self._finder = StreamFinder(name, 'Markers')   # a bad name fails here, at once
        self.clocksync, self.resolve_timeout = clocksync, resolve_timeout
        self.desc: StreamDescription | None = None
        self.count = 0                                  # markers pulled
        self._inlet: pylsl.StreamInlet | None = None
        self._lock = threading.Lock()
        self._pending: tuple[pylsl.StreamInlet, StreamDescription] | None = None
        self._news: list[tuple[str, str]] = []          # (level, log line), oldest first
        self._lost_uids: set[str] = set()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._search()

    def _search(self) -> None:
        """Look for the stream in a background thread (the last one has ended)."""
        def run() -> None:
            started, reported = time.monotonic(), False
            while not self._stop.is_set():
                info = self._finder.newest(exclude_uids=tuple(self._lost_uids))
                if info is not None:
                    try:
                        found = open_inlet(info, max_buflen=1.0, dejitter=False,
                                           clocksync=clocksync_for(info, self.clocksync))
                    except EEGError as exc:
                        self._say(str(exc), 'warning')
                        self._stop.wait(1.0)
                        continue
                    with self._lock:
                        self._pending = found
                    return
                if not reported and time.monotonic() - started > self.resolve_timeout:
                    self._say(f"No LSL marker stream named '{self.name}' after "
                              f'{self.resolve_timeout:g} s; still looking. Start the marker '
                              'sender, or set marker_stream to its name (none: no markers).',
                              'warning')
                    reported = True
                self._stop.wait(0.1)

        self._thread = threading.Thread(target=run, name='eeg-markers-search', daemon=True)
        self._thread.start()

    def _say(self, line: str, level: str = 'info') -> None:
        with self._lock:
            self._news.append((level, line))

    def poll(self) -> tuple[list[Marker], list[tuple[str, str]]]:
        """Markers that arrived (never blocks), and news for the log as ``(level, line)``
        (``'info'`` or ``'warning'``): the stream found, not found yet, or lost."""
        with self._lock:
            pending, self._pending = self._pending, None
        if pending is not None:
            self._inlet, self.desc = pending
            self._say(f'Relaying the LSL marker stream {self.desc.summary()}.')
        markers: list[Marker] = []
        if self._inlet is not None:
            try:
                samples, stamps = self._inlet.pull_chunk(timeout=0.0)
            except LostError:
                assert self.desc is not None
                self._say(f"The LSL marker stream '{self.desc.name}' is lost (its sender closed "
                          f'it after {self.count} marker(s)); looking for it again.', 'warning')
                self._lost_uids.add(self.desc.uid)
                self._inlet = None
                self._search()
                samples, stamps = [], []
            markers = [Marker(str(s[0]) if s else '', float(t))
                       for s, t in zip(samples, stamps, strict=True)]
            self.count += len(markers)
        with self._lock:
            news, self._news = self._news, []
        return markers, news

    def close(self) -> None:
        """Stop searching and close the inlet (the search thread ends within 0.1 s)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=0.1)
        if self._inlet is not None:
            self._inlet.close_stream()
            self._inlet = None
        if self._thread is None or not self._thread.is_alive():
            self._finder.close()
