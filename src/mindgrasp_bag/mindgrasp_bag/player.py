"""The player core: replays a bag's messages with their original timing through callbacks.

ROS-free: the player node passes ``publish(topic, cdr_bytes)`` and ``publish_clock(ns)``
callbacks; tests pass recording functions. Message ``k`` is published at wall time
``t0 + (stamp_k - start) / rate``, where ``start`` is the bag start plus ``start_offset``.
"""

from __future__ import annotations

import collections
import contextlib
import os
import re
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from .errors import BagError
from .reader import BagReader, TopicInfo
from .typestore import typestore as default_typestore

#: Messages (and bytes) read ahead of the playback position, as rosbag2's read-ahead queue.
READ_AHEAD = 200
READ_AHEAD_BYTES = 64 << 20

__all__ = ['PlayStats', 'Player', 'parse_remaps', 'type_problem']


@dataclass
class PlayStats:
    """What a playback did: messages per output topic, skipped topics with the reason."""

    published: dict[str, int] = field(default_factory=dict)
    skipped: dict[str, str] = field(default_factory=dict)
    loops: int = 0
    max_late_ms: float = 0.0         # worst lateness of a publication behind its schedule (ms)
    stopped: bool = False
    notes: list[str] = field(default_factory=list)


@contextlib.contextmanager
def _realtime(priority: int) -> Iterator[str | None]:
    """SCHED_FIFO for the calling thread inside the block (restored after); yields a problem."""
    if not hasattr(os, 'sched_setscheduler'):
        yield 'Real-time priority is not available on this system; playing with normal priority.'
        return
    try:
        old_policy, old_param = os.sched_getscheduler(0), os.sched_getparam(0)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(min(int(priority), 99)))
    except (OSError, ValueError) as exc:
        yield (f'Real-time priority {priority} was refused ({exc}); playing with normal '
               'priority (run as root or grant CAP_SYS_NICE for tighter timing).')
        return
    try:
        yield None
    finally:
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, old_policy, old_param)


def type_problem(info: TopicInfo, store: Any = None) -> str | None:
    """Why a topic cannot be replayed with the type store (None when it can).

    A topic is playable when it is CDR, its type is in the store, and the recorded type hash (when
    the bag has one) equals the store's, so the bytes mean what subscribers expect.
    """
    store = store or default_typestore()
    if info.serialization_format != 'cdr':
        return f'its serialization format is {info.serialization_format!r}, not cdr'
    if info.type not in store.fielddefs:
        return f'its message type {info.type} is unknown here'
    if info.type_description_hash and info.type_description_hash.startswith('RIHS01_'):
        ours = store.hash_rihs01(info.type)
        if ours != info.type_description_hash:
            return (f'its message type {info.type} was recorded with another definition '
                    f'(hash {info.type_description_hash[:15]}..., ours {ours[:15]}...)')
    return None


def parse_remaps(items: Iterable[str]) -> dict[str, str]:
    """``['/from:=/to', ...]`` -> ``{'/from': '/to'}``.

    Raises
    ------
    BagError
        An item without ``:=``.
    """
    out = {}
    for item in items:
        source, sep, target = item.partition(':=')
        if not sep or not source or not target:
            msg = f'The remap {item!r} is not valid; write it as /from:=/to.'
            raise BagError(msg)
        out[source] = target
    return out


class Player:
    """Plan and run the playback of one bag.

    Parameters
    ----------
    reader
        An opened :class:`BagReader`.
    rate
        Playback speed factor (2.0 = twice as fast); > 0.
    loop
        Start again at the end, until stopped.
    start_offset
        Skip this much of the bag's beginning (s).
    topics
        Play only these topics (default: all).
    regex
        Play only topics matching this regular expression.
    exclude_regex
        Do not play topics matching this regular expression.
    remap
        Output topic names, ``{'/from': '/to'}``.
    can_publish
        ``f(topic_info) -> None or reason``: says whether the ROS layer can publish
        a topic's type; default: the type is in the type store with the bag's type hash.
    typestore
        The type store for the default ``can_publish``.
    """

    def __init__(self, reader: BagReader, *, rate: float = 1.0, loop: bool = False,
                 start_offset: float = 0.0, topics: Iterable[str] | None = None,
                 regex: str = '', exclude_regex: str = '',
                 remap: dict[str, str] | None = None,
                 can_publish: Callable[[TopicInfo], str | None] | None = None,
                 typestore: Any = None) -> None:
        if not rate > 0:
            msg = f'The playback rate must be > 0 (1.0 = real time); {rate} is invalid.'
            raise BagError(msg)
        if start_offset < 0:
            msg = f'The start offset must be >= 0 s; {start_offset} is invalid.'
            raise BagError(msg)
        self.reader = reader
        self.rate = float(rate)
        self.loop = bool(loop)
        self.start_offset_ns = int(start_offset * 1e9)
        self.remap = dict(remap or {})
        self.typestore = typestore
        self._can_publish = can_publish or (lambda info: type_problem(info, typestore))
        try:
            include = re.compile(regex) if regex else None
            exclude = re.compile(exclude_regex) if exclude_regex else None
        except re.error as exc:
            msg = f'The topic regular expression is not valid ({exc}); fix its syntax.'
            raise BagError(msg) from None
        wanted = None if topics is None else list(topics)
        if wanted is not None:
            missing = [t for t in wanted if t not in reader.topics]
            if missing:
                msg = (f'The bag {reader.path} has no topic {", ".join(missing)}; its topics '
                       f'are: {", ".join(sorted(reader.topics)) or "none"}.')
                raise BagError(msg)
        self.selected: list[TopicInfo] = [
            info for name, info in reader.topics.items()
            if (wanted is None or name in wanted)
            and (include is None or include.search(name))
            and not (exclude is not None and exclude.search(name))]
        self.skipped: dict[str, str] = {}
        self.playable: dict[str, TopicInfo] = {}
        for info in self.selected:
            reason = self._can_publish(info)
            if reason:
                self.skipped[info.name] = reason
            else:
                self.playable[info.name] = info

    def output_topic(self, topic: str) -> str:
        """The topic a bag topic is published on (after remapping)."""
        return self.remap.get(topic, topic)

    def skipped_report(self) -> list[str]:
        """One sentence per skipped topic, for the user."""
        return [f'Skipping {topic}: {reason}.' for topic, reason in self.skipped.items()]

    def run(self, publish: Callable[[str, bytes], None], *,
            publish_clock: Callable[[int], None] | None = None, clock_hz: float = 40.0,
            stop: threading.Event | None = None, max_loops: int = 0, priority: int = 0,
            now: Callable[[], int] = time.monotonic_ns,
            sleep: Callable[[float], None] = time.sleep) -> PlayStats:
        """Play until the end (or ``stop`` is set; with ``loop``, until stopped or max_loops).

        Parameters
        ----------
        publish
            Called with (output topic, CDR bytes) for every message.
        publish_clock
            Called with the bag time (ns) at ``clock_hz`` when given (/clock).
        clock_hz
            /clock publication rate (Hz).
        stop
            Set it to stop early.
        max_loops
            With ``loop``, stop after this many passes (0 = endless).
        priority
            Real-time (SCHED_FIFO) priority 1-99 of the calling thread while playing;
            0 = normal scheduling. On a loaded machine normal scheduling wakes the player up
            to several ms late; real-time priority keeps it within ~0.1 ms. Needs root or
            CAP_SYS_NICE; without, playback runs normally and ``stats.notes`` says so.
        """
        if priority <= 0:
            return self._run(publish, publish_clock, clock_hz, stop, max_loops, now, sleep)
        with _realtime(priority) as problem:
            stats = self._run(publish, publish_clock, clock_hz, stop, max_loops, now, sleep)
        if problem:
            stats.notes.append(problem)
        return stats

    def _run(self, publish: Callable[[str, bytes], None],
             publish_clock: Callable[[int], None] | None, clock_hz: float,
             stop: threading.Event | None, max_loops: int, now: Callable[[], int],
             sleep: Callable[[float], None]) -> PlayStats:
        stats = PlayStats(skipped=dict(self.skipped))
        if not self.playable:
            return stats
        clock_period = int(1e9 / clock_hz) if publish_clock is not None and clock_hz > 0 else 0
        start = self.reader.start_ns + self.start_offset_ns
        while True:
            source = iter(self.reader.messages(self.playable, start_ns=start))
            buffer: collections.deque = collections.deque()
            buffered = [0]   # bytes in the buffer

            def fill(limit: int, source=source, buffer=buffer, buffered=buffered) -> bool:
                """Read up to ``limit`` messages ahead; False once the bag is exhausted."""
                while len(buffer) < limit and buffered[0] < READ_AHEAD_BYTES:
                    item = next(source, None)
                    if item is None:
                        return False
                    buffer.append(item)
                    buffered[0] += len(item[2])
                return True

            more = fill(READ_AHEAD)
            if not buffer:
                return stats
            # The clock starts once messages are in hand, so opening the bag (indexes, first
            # chunk) does not delay the first publications.
            wall0 = now()
            next_clock = wall0
            while buffer:
                topic, stamp, data = buffer.popleft()
                buffered[0] -= len(data)
                target = wall0 + int((stamp - start) / self.rate)
                while True:
                    if stop is not None and stop.is_set():
                        stats.stopped = True
                        return stats
                    t = now()
                    if clock_period and t >= next_clock:
                        publish_clock(start + int((t - wall0) * self.rate))  # type: ignore[misc]
                        next_clock += clock_period * max(1, (t - next_clock) // clock_period)
                    remaining = target - t
                    if remaining <= 0:
                        break
                    if more and len(buffer) < READ_AHEAD and remaining > 2_000_000:
                        # Read the bag while waiting, one message at a time, never late.
                        more = fill(len(buffer) + 1)
                        continue
                    wait = remaining if not clock_period else min(remaining, next_clock - t)
                    sleep(min(wait, 50_000_000) / 1e9)
                out = self.output_topic(topic)
                publish(out, data)
                stats.published[out] = stats.published.get(out, 0) + 1
                stats.max_late_ms = max(stats.max_late_ms, (now() - target) / 1e6)
                if more and not buffer:
                    more = fill(1)   # the bag is read slower than played: read on demand
            stats.loops += 1
            if not self.loop or (max_loops and stats.loops >= max_loops):
                return stats
