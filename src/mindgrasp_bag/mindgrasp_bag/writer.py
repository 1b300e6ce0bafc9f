"""rosbag2 bag writer: a directory with metadata.yaml (version 9) and MCAP files (ros2 profile).

The MCAP files are written with the ``mcap`` library rather than ``rosbags.rosbag2.Writer``:
rosbags closes a chunk only when it exceeds 1 MiB and cannot flush on demand or split files, so a
recorder killed with SIGKILL would lose everything since the last chunk (or the whole file, since
rosbags writes schemas and channels inside the first chunk). ``mcap.writer.Writer.flush()`` ends
the current chunk and writes it out, which bounds the loss to ``flush_interval`` seconds.
Message definitions and type hashes come from the rosbags type store, in rosbag2's format.
"""

from __future__ import annotations

import time
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any, BinaryIO

from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter

from .errors import BagError
from .mcap_scan import read_mcap_contents
from .metadata import FileStats, TopicStats, build_metadata, dump_metadata, write_metadata
from .qos import dump_offered_qos, qos_to_dict
from .typestore import typestore as default_typestore

__all__ = ['BagWriter']

_LIBRARY = 'mindgrasp-ros bag writer (mcap python)'
_COMPRESSION = {'none': CompressionType.NONE, '': CompressionType.NONE,
                'zstd': CompressionType.ZSTD, 'lz4': CompressionType.LZ4}


@dataclass
class _Topic:
    stats: TopicStats
    msgdef: str


class BagWriter:
    """Write a rosbag2 bag incrementally: open, add_topic, write, close (or a ``with`` block).

    Parameters
    ----------
    path
        Bag directory to create (must not exist).
    typestore
        Rosbags type store giving message definitions and type hashes (default: the
        project's store, ROS 2 Jazzy types + mindgrasp_msgs).
    chunk_size
        Bytes of messages per MCAP chunk before it is written out.
    compression
        'none', 'zstd' or 'lz4': MCAP chunk compression (what rosbag2 does with the
        zstd_fast storage preset; metadata compression fields stay empty, as in rosbag2).
    flush_interval
        Longest time (s) written messages stay in memory; bounds what a SIGKILL
        loses. 0 flushes after every message.
    max_bag_size
        Start a new .mcap file when the current one reaches this size (bytes);
        0 = never.
    max_bag_duration
        Start a new .mcap file when the current one spans this long (s);
        0 = never.
    custom_data
        String pairs stored in metadata.yaml ``custom_data``.
    """

    def __init__(self, path: Path | str, *, typestore: Any = None, chunk_size: int = 1 << 20,
                 compression: str = 'none', flush_interval: float = 1.0,
                 max_bag_size: int = 0, max_bag_duration: float = 0.0,
                 custom_data: dict[str, str] | None = None) -> None:
        self.path = Path(path)
        if compression not in _COMPRESSION:
            msg = (f"The compression {compression!r} is not supported; use 'none', 'zstd' "
                   "or 'lz4'.")
            raise BagError(msg)
        if chunk_size <= 0:
            msg = f'The chunk size must be a positive number of bytes; {chunk_size} is invalid.'
            raise BagError(msg)
        if flush_interval < 0 or max_bag_size < 0 or max_bag_duration < 0:
            msg = ('flush_interval, max_bag_size and max_bag_duration must be >= 0 (0 = off); '
                   f'got {flush_interval}, {max_bag_size}, {max_bag_duration}.')
            raise BagError(msg)
        self.typestore = typestore or default_typestore()
        self.chunk_size = int(chunk_size)
        self.compression = compression if compression not in ('', 'none') else 'none'
        self.flush_interval = float(flush_interval)
        self.max_bag_size = int(max_bag_size)
        self.max_bag_duration_ns = int(max_bag_duration * 1e9)
        self.custom_data = dict(custom_data or {})
        self.topics: dict[str, _Topic] = {}
        self.files: list[FileStats] = []
        self.bytes_written = 0          # message payload bytes
        self._stream: BinaryIO | None = None
        self._mcap: McapWriter | None = None
        self._schema_ids: dict[str, int] = {}
        self._channel_ids: dict[str, int] = {}
        self._unflushed = 0
        self._last_flush = time.monotonic()
        self._counts_before_file: dict[str, int] = {}
        self._opened = False
        self._closed = False

    # -- state machine --------------------------------------------------------------------------
    def open(self) -> None:
        """Create the bag directory and its first .mcap file."""
        if self._opened:
            msg = f'The bag {self.path} is already open.'
            raise BagError(msg)
        try:
            self.path.mkdir(parents=True, exist_ok=False)
        except FileExistsError:
            msg = (f'{self.path} exists already; choose another output path (bags are never '
                   'overwritten).')
            raise BagError(msg) from None
        except OSError as exc:
            msg = f'Cannot create the bag directory {self.path}: {exc.strerror}.'
            raise BagError(msg) from exc
        self._opened = True
        self._open_file()

    def _check_open(self) -> None:
        if not self._opened or self._closed or self._mcap is None:
            msg = f'The bag {self.path} is not open; call open() first (or use a with block).'
            raise BagError(msg)

    def _open_file(self) -> None:
        name = f'{self.path.name}_{len(self.files)}.mcap'
        try:
            # Buffered: write() then loops until all bytes are written or raises (ENOSPC).
            self._stream = (self.path / name).open('xb', buffering=1 << 20)
        except OSError as exc:
            msg = f'Cannot create {self.path / name}: {exc.strerror}.'
            raise BagError(msg) from exc
        self._mcap = McapWriter(self._stream, chunk_size=self.chunk_size,
                                compression=_COMPRESSION[self.compression])
        self._mcap.start(profile='ros2', library=_LIBRARY)
        self.files.append(FileStats(name))
        # per-topic counts in the finished files: abort() adds what the current file holds
        self._counts_before_file = {t: topic.stats.message_count
                                    for t, topic in self.topics.items()}
        self._schema_ids = {}
        self._channel_ids = {}
        for topic in self.topics.values():
            self._register(topic)
        self._io(self.flush)

    def _register(self, topic: _Topic) -> None:
        assert self._mcap is not None
        msgtype = topic.stats.type
        if msgtype not in self._schema_ids:
            self._schema_ids[msgtype] = self._mcap.register_schema(
                msgtype, 'ros2msg', topic.msgdef.encode())
        metadata = {'offered_qos_profiles': dump_offered_qos(topic.stats.offered_qos_profiles),
                    'topic_type_hash': topic.stats.type_description_hash}
        self._channel_ids[topic.stats.name] = self._mcap.register_channel(
            topic.stats.name, 'cdr', self._schema_ids[msgtype], metadata)

    def add_topic(self, topic: str, msgtype: str, *, offered_qos_profiles: Any = (),
                  msgdef: str | None = None, type_hash: str | None = None) -> None:
        """Declare a topic before writing to it.

        Parameters
        ----------
        topic
            Topic name, e.g. '/eeg/raw'.
        msgtype
            ROS 2 type name, 'pkg/msg/Type'.
        offered_qos_profiles
            The publishers' QoS (rclpy QoSProfile, rosbags Qos or dicts).
        msgdef
            Concatenated message definition; default: generated from the type store.
        type_hash
            'RIHS01_...' type description hash; default: from the type store.

        Raises
        ------
        BagError
            Unknown type without msgdef, or the topic exists with another type.
        """
        self._check_open()
        if topic in self.topics:
            if self.topics[topic].stats.type != msgtype:
                msg = (f'The topic {topic} is recorded as {self.topics[topic].stats.type} and '
                       f'cannot also be recorded as {msgtype}; record one type per topic.')
                raise BagError(msg)
            return
        if msgdef is None or type_hash is None:
            if msgtype not in self.typestore.fielddefs:
                msg = (f'The message type {msgtype} of {topic} is not in the type store, so its '
                       'definition cannot be recorded; add its .msg to the type store or pass '
                       'msgdef and type_hash.')
                raise BagError(msg)
            msgdef = msgdef if msgdef is not None else (
                self.typestore.generate_msgdef(msgtype, ros_version=2)[0])
            type_hash = type_hash if type_hash is not None else (
                self.typestore.hash_rihs01(msgtype))
        stats = TopicStats(topic, msgtype, [qos_to_dict(q) for q in offered_qos_profiles],
                           type_hash)
        self.topics[topic] = _Topic(stats, msgdef)
        self._io(self._register, self.topics[topic])

    def write(self, topic: str, timestamp: int, data: bytes | memoryview,
              publish_time: int | None = None) -> None:
        """Write one serialized (CDR) message.

        Parameters
        ----------
        topic
            A topic declared with :meth:`add_topic`.
        timestamp
            Receive time (ns since the epoch or since sim start); MCAP log_time.
        data
            CDR bytes as published.
        publish_time
            Send time (ns) when known; default ``timestamp``.

        Raises
        ------
        BagError
            Bag not open, topic not declared, or a write error (``__cause__`` is the
            OSError, e.g. ENOSPC for a full disk).
        """
        self._check_open()
        channel = self._channel_ids.get(topic)
        if channel is None:
            msg = f'The topic {topic} was not added to the bag; call add_topic() first.'
            raise BagError(msg)
        current = self.files[-1]
        if current.message_count and self._should_split(current, timestamp):
            self._io(self._split)
            current = self.files[-1]
            channel = self._channel_ids[topic]
        self._io(self._mcap.add_message, channel, timestamp, data,  # type: ignore[union-attr]
                 timestamp if publish_time is None else publish_time)
        current.add(timestamp)
        self.topics[topic].stats.message_count += 1
        self.bytes_written += len(data)
        self._unflushed += len(data)
        self.maybe_flush()

    def _should_split(self, current: FileStats, timestamp: int) -> bool:
        if (self.max_bag_size and self._stream is not None
                and self._stream.tell() + self._unflushed >= self.max_bag_size):
            return True
        return bool(self.max_bag_duration_ns
                    and timestamp - current.start_ns >= self.max_bag_duration_ns)

    def _split(self) -> None:
        self._finish_file()
        self._open_file()

    def maybe_flush(self, now: float | None = None) -> bool:
        """Flush when unflushed messages are older than ``flush_interval``; True if it did."""
        if not self._unflushed:
            return False
        now = time.monotonic() if now is None else now
        if now - self._last_flush >= self.flush_interval:
            self._io(self.flush)
            return True
        return False

    def flush(self) -> None:
        """End the current MCAP chunk and hand everything written so far to the OS."""
        if self._mcap is None:
            return
        self._mcap.flush()
        self._unflushed = 0
        self._last_flush = time.monotonic()

    def _finish_file(self) -> None:
        assert self._mcap is not None and self._stream is not None
        self._mcap.add_metadata('rosbag2', {'serialized_metadata': self._metadata_text()})
        self._mcap.finish()
        self._stream.close()
        self._mcap = self._stream = None

    def _metadata(self) -> dict[str, Any]:
        return build_metadata(self.files, [t.stats for t in self.topics.values()],
                              custom_data=self.custom_data)

    def _metadata_text(self) -> str:
        return dump_metadata(self._metadata()['rosbag2_bagfile_information']).strip()

    def close(self) -> None:
        """Finish the MCAP file (summary, footer) and write metadata.yaml."""
        if self._closed or not self._opened:
            return
        try:
            self._io(self._finish_file)
            self._io(write_metadata, self.path, self._metadata())
        except BaseException:
            self.abort()        # counts made true, what reached the disk kept
            raise
        self._closed = True

    def abort(self) -> None:
        """Stop after an error: keep the flushed data, make the counts true, try to leave a
        metadata.yaml.

        Messages handed to the MCAP writer but not on disk when the error came (a chunk cut by
        a full disk) are not in the bag: the current file is read back, so ``files``, the topic
        counts and metadata.yaml say what is recoverable. The file gets no summary, so readers
        scan it (:mod:`.mcap_scan`); ``mindgrasp bag reindex`` finishes it once there is space.
        """
        if self._closed:
            return
        self._closed = True
        if self._stream is not None:
            with suppress(OSError, ValueError):
                self._stream.close()
        self._mcap = self._stream = None
        if self.files:
            self._recount(self.path / self.files[-1].path)
        with suppress(OSError):
            write_metadata(self.path, self._metadata())

    def _recount(self, path: Path) -> None:
        """Set the current file's and the topics' counts to what ``path`` really holds."""
        try:
            contents = read_mcap_contents(path)
        except BagError:        # not even the header reached the disk
            contents = None
        current = self.files[-1]
        by_topic: dict[str, int] = {}
        if contents is not None:
            current.message_count = contents.message_count
            current.start_ns, current.end_ns = contents.start_ns, contents.end_ns
            for cid, channel in contents.channels.items():
                by_topic[channel.topic] = (by_topic.get(channel.topic, 0)
                                           + contents.channel_counts.get(cid, 0))
        else:
            current.message_count = current.start_ns = current.end_ns = 0
        for name, topic in self.topics.items():
            topic.stats.message_count = self._counts_before_file.get(name, 0) + \
                by_topic.get(name, 0)

    @property
    def is_open(self) -> bool:
        """True between open() and close()/abort()."""
        return self._opened and not self._closed

    def _io(self, func: Any, *args: Any) -> Any:
        try:
            return func(*args)
        except OSError as exc:
            where = self._stream.name if self._stream is not None else self.path
            msg = (f'Writing the bag file {where} failed: {exc.strerror or exc}. '
                   + ('The disk is full; free space or record to another disk.'
                      if exc.errno == 28 else 'Check the disk and the permissions.'))
            raise BagError(msg) from exc

    def __enter__(self) -> BagWriter:
        self.open()
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
