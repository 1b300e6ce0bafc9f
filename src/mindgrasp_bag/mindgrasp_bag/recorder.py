"""The recorder core: subscription callbacks hand CDR bytes over, a thread writes the bag.

ROS-free, so the node, the CLI, the benchmark and the unit tests share it. Callbacks never block:
:meth:`Recorder.push` appends to a queue bounded in bytes; a full queue drops the message and
counts it. The writer thread drains the queue, flushes the bag at ``flush_interval``, checks EEG
chunks for sample gaps, and on a write error (full disk) stops recording, keeps what is written
readable, and reports the error through ``on_error`` while the rest of the process runs on.
"""

from __future__ import annotations

import collections
import errno
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from .errors import BagError
from .writer import BagWriter

__all__ = ['Recorder', 'TopicCounters']

EEG_CHUNK = 'mindgrasp_msgs/msg/EEGChunk'


@dataclass
class TopicCounters:
    """Per-topic counters (messages unless stated)."""

    received: int = 0
    written: int = 0
    bytes_written: int = 0
    dropped_queue_full: int = 0      # messages dropped because the write queue was full
    lost_disk_fault: int = 0         # messages lost to a write error: not on disk when it came,
                                     # queued then, or received after it
    samples_missing: int = 0         # EEG samples missing between chunks (sequence gaps)
    gaps: int = 0                    # number of sequence gaps seen


class Recorder:
    """Queue + writer thread in front of a :class:`BagWriter`.

    Parameters
    ----------
    writer
        A bag writer, not yet opened (the thread opens and closes it).
    max_queue_bytes
        Memory for messages waiting to be written (bytes); beyond it new
        messages are dropped and counted. Default 512 MiB (~8 s of 30 Hz RGB-D).
    on_error
        Called once, from the writer thread, with a sentence when recording stops
        because of an error (e.g. disk full).
    typestore
        Rosbags type store used to decode EEG chunks for the gap check (default: the
        writer's).
    """

    def __init__(self, writer: BagWriter, *, max_queue_bytes: int = 512 << 20,
                 on_error: Callable[[str], None] | None = None, typestore: Any = None) -> None:
        if max_queue_bytes <= 0:
            msg = f'max_queue_bytes must be positive; {max_queue_bytes} is invalid.'
            raise BagError(msg)
        self.writer = writer
        self.max_queue_bytes = int(max_queue_bytes)
        self.on_error = on_error
        self.typestore = typestore or writer.typestore
        self.counters: dict[str, TopicCounters] = {}
        self.error: str | None = None
        self._queue: collections.deque = collections.deque()
        self._queued_bytes = 0
        self._lock = threading.Lock()
        self._wake = threading.Event()
        self._stopping = False
        self._thread: threading.Thread | None = None
        self._types: dict[str, str] = {}
        self._next_sample: dict[str, int] = {}
        self._reports: list[str] = []
        self._reported_drops: dict[str, int] = {}
        self.max_queued_bytes = 0    # high-water mark (bytes)

    # -- called from any thread ---------------------------------------------------------------
    def start(self) -> None:
        """Open the bag and start the writer thread."""
        self.writer.open()
        self._thread = threading.Thread(target=self._run, name='bag-writer', daemon=True)
        self._thread.start()

    def add_topic(self, topic: str, msgtype: str, offered_qos_profiles: Any = ()) -> None:
        """Declare a topic; queued in order with the messages, so push() may follow at once."""
        with self._lock:
            self.counters.setdefault(topic, TopicCounters())
            self._types[topic] = msgtype
            self._queue.append(('topic', topic, msgtype, list(offered_qos_profiles)))
        self._wake.set()

    def push(self, topic: str, data: bytes | memoryview, timestamp_ns: int | None = None,
             publish_time_ns: int | None = None) -> bool:
        """Queue one message for writing; never blocks. False when dropped (or stopped).

        Parameters
        ----------
        topic
            A topic passed to :meth:`add_topic` before.
        data
            CDR bytes of the message.
        timestamp_ns
            Receive time (ns); default now (system clock). MCAP log_time.
        publish_time_ns
            Send time (ns) when the middleware gives it (DDS source
            timestamp); MCAP publish_time, as rosbag2 Jazzy stores it.
        """
        if timestamp_ns is None:
            timestamp_ns = time.time_ns()
        size = len(data)
        with self._lock:
            counters = self.counters[topic]
            counters.received += 1
            if self.error is not None:
                counters.lost_disk_fault += 1
                return False
            if self._stopping:
                return False
            if self._queued_bytes + size > self.max_queue_bytes:
                counters.dropped_queue_full += 1
                return False
            self._queued_bytes += size
            self.max_queued_bytes = max(self.max_queued_bytes, self._queued_bytes)
            self._queue.append(('msg', topic, timestamp_ns, data, publish_time_ns))
        self._wake.set()
        return True

    def stop(self, timeout: float = 30.0) -> dict[str, TopicCounters]:
        """Write what is queued, close the bag and return the counters."""
        with self._lock:
            self._stopping = True
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout)
            if self._thread.is_alive():
                msg = (f'The bag writer did not finish within {timeout:.0f} s; the disk is too '
                       'slow for the recorded data rate.')
                raise BagError(msg)
        return self.counters

    def reports(self) -> list[str]:
        """New drop and gap reports since the last call (sentences; for the node's log)."""
        with self._lock:
            out, self._reports = self._reports, []
            for topic, c in self.counters.items():
                new = c.dropped_queue_full - self._reported_drops.get(topic, 0)
                if new:
                    self._reported_drops[topic] = c.dropped_queue_full
                    out.append(f'{topic}: dropped {new} message(s) because the write queue was '
                               f'full ({self.max_queue_bytes / 2**20:.0f} MiB); the disk is '
                               'slower than the data rate, record fewer topics or use a '
                               'faster disk.')
        return out

    @property
    def queued_bytes(self) -> int:
        """Bytes waiting to be written."""
        return self._queued_bytes

    @property
    def running(self) -> bool:
        """True while the writer thread runs."""
        return self._thread is not None and self._thread.is_alive()

    # -- writer thread ---------------------------------------------------------------------------
    def _run(self) -> None:
        writer = self.writer
        queue = self._queue
        try:
            while True:
                while queue:
                    item = queue.popleft()
                    if item[0] == 'msg':
                        _, topic, timestamp, data, publish_time = item
                        with self._lock:
                            self._queued_bytes -= len(data)
                        writer.write(topic, timestamp, data, publish_time)
                        counters = self.counters[topic]
                        counters.written += 1
                        counters.bytes_written += len(data)
                        if self._types[topic] == EEG_CHUNK:
                            self._check_eeg(topic, data)
                    else:
                        _, topic, msgtype, qos = item
                        writer.add_topic(topic, msgtype, offered_qos_profiles=qos)
                writer.maybe_flush()
                if self._stopping and not queue:
                    break
                self._wake.wait(0.05)
                self._wake.clear()
            writer.close()
        except BagError as exc:
            self._fail(exc)
        except Exception as exc:  # the thread must report, not die silently
            self._fail(exc)

    def _fail(self, exc: BaseException) -> None:
        cause = exc.__cause__
        full = isinstance(cause, OSError) and cause.errno == errno.ENOSPC
        with self._lock:
            self.error = (f'Recording stopped: {exc}' + (
                '' if full or isinstance(exc, BagError) else
                ' This is a bug in the recorder; please report it with the bag.'))
            queued = 0
            for item in self._queue:
                if item[0] == 'msg':
                    self.counters[item[1]].lost_disk_fault += 1
                    queued += 1
            self._queue.clear()
            self._queued_bytes = 0
        self.writer.abort()     # reads back what reached the disk
        unwritten = 0
        for topic, counters in self.counters.items():
            stats = self.writer.topics.get(topic)
            on_disk = stats.stats.message_count if stats is not None else 0
            lost = max(0, counters.written - on_disk)
            unwritten += lost
            counters.lost_disk_fault += lost
            counters.written = on_disk
        kept = sum(c.written for c in self.counters.values())
        self.error += (f' {kept} message(s) are on disk and recoverable in {self.writer.path}; '
                       f'{unwritten} written before the fault did not reach the disk and '
                       f'{queued} queued were not written (`mindgrasp bag reindex` finishes '
                       'the bag once there is space).')
        if self.on_error is not None:
            self.on_error(self.error)

    def _check_eeg(self, topic: str, data: bytes) -> None:
        try:
            msg = self.typestore.deserialize_cdr(data, EEG_CHUNK)
        except Exception:  # a malformed message is recorded as is
            return
        first, n = int(msg.first_sample_index), int(msg.n_samples)
        expected = self._next_sample.get(topic)
        if expected is not None and first > expected:
            counters = self.counters[topic]
            counters.gaps += 1
            counters.samples_missing += first - expected
            with self._lock:
                self._reports.append(
                    f'{topic}: {first - expected} EEG sample(s) missing before sample {first} '
                    '(the amplifier stream or the network dropped them).')
        self._next_sample[topic] = first + n
