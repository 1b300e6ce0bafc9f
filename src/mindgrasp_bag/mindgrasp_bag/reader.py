"""Read any rosbag2 bag: ours, ``ros2 bag`` (sqlite3 or MCAP), rosbags; finished or not.

Complete bags are read with ``rosbags.rosbag2.Reader`` (both storage plugins, all compression
modes). A bag whose recorder was killed (MCAP files without summary, maybe no metadata.yaml) is
read by scanning its MCAP files (:mod:`.mcap_scan`), which recovers every complete record.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any

from rosbags.rosbag2 import Reader
from rosbags.rosbag2.errors import ReaderError

from .errors import BagError
from .mcap_scan import (
    CORRUPT_RECORD_ERRORS,
    is_finished,
    iter_mcap_messages,
    read_mcap_contents,
)
from .metadata import METADATA_FILE, load_metadata, mcap_files, rebuild_metadata
from .qos import parse_offered_qos

__all__ = ['BagReader', 'TopicInfo']


@dataclass
class TopicInfo:
    """A topic of a bag."""

    name: str
    type: str
    message_count: int = 0
    offered_qos_profiles: list[dict[str, Any]] = field(default_factory=list)
    type_description_hash: str = ''
    msgdef: str = ''                 # concatenated message definition ('' when the bag has none)
    serialization_format: str = 'cdr'


class BagReader:
    """Open a bag directory (or a single .mcap/.db3 file) and iterate its messages in time order.

    Attributes (after :meth:`open`): ``topics`` (name -> :class:`TopicInfo`), ``start_ns``,
    ``end_ns``, ``message_count``, ``storage`` ('mcap' or 'sqlite3'), ``files``, ``notes``
    (what was recovered or rebuilt, as sentences) and ``complete`` (False when recovered by a
    scan of unfinished files).
    """

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self.topics: dict[str, TopicInfo] = {}
        self.start_ns = 0
        self.end_ns = 0
        self.message_count = 0
        self.storage = ''
        self.files: list[Path] = []
        self.notes: list[str] = []
        self.complete = True
        self._reader: Reader | None = None
        self._scan_files: list[Path] = []

    @property
    def duration_ns(self) -> int:
        """Time between the first and the last message (ns)."""
        return max(0, self.end_ns - self.start_ns)

    def open(self) -> BagReader:
        """Read the bag's metadata (and the files' summaries).

        Raises:
            BagError: missing path, not a bag, or a corrupt bag; the message says what to do.
        """
        if not self.path.exists():
            msg = (f'The bag {self.path} does not exist; pass the path of a bag directory (the '
                   'one holding metadata.yaml) or of an .mcap/.db3 file.')
            raise BagError(msg)
        if self.path.is_dir():
            self.files = mcap_files(self.path)
            has_metadata = (self.path / METADATA_FILE).exists()
            if not has_metadata and not self.files:
                db3 = sorted(self.path.glob('*.db3'))
                if db3:
                    msg = (f'{self.path} has no metadata.yaml; sqlite3 bags cannot be rebuilt, '
                           f'open the storage file itself instead ({db3[0]}).')
                else:
                    msg = (f'{self.path} is not a rosbag2 bag (no metadata.yaml, no .mcap '
                           'file); pass the directory that `mindgrasp bag record` or '
                           '`ros2 bag record` created.')
                raise BagError(msg)
            unfinished = [p for p in self.files if not is_finished(p)]
            if has_metadata and not unfinished:
                try:
                    self._open_rosbags(self.path)
                except BagError as exc:
                    if not self.files:
                        raise
                    # read what can be read: a damaged summary or metadata.yaml does not
                    # make the records unreadable
                    self.notes.append(f'{exc} The files were read by a scan instead.')
                    self._open_scan(self.files, [], has_metadata)
            else:
                self._open_scan(self.files, unfinished, has_metadata)
        elif self.path.suffix == '.mcap':
            self.files = [self.path]
            if is_finished(self.path):
                self._open_rosbags(self.path)
            else:
                self._open_scan(self.files, self.files, False)
        elif self.path.suffix == '.db3':
            self.files = [self.path]
            self._open_rosbags(self.path)
        else:
            msg = (f'{self.path} is not a bag: expected a directory with metadata.yaml, an .mcap '
                   'or a .db3 file.')
            raise BagError(msg)
        return self

    def _open_rosbags(self, path: Path) -> None:
        try:
            reader = Reader(path)
            reader.open()
        except (ReaderError, FileNotFoundError, OSError, KeyError, ValueError) as exc:
            msg = (f'The bag {path} cannot be read: {exc} It is corrupt or incomplete; for an '
                   f'MCAP bag, delete its metadata.yaml and run `mindgrasp bag reindex {path}` to '
                   'rebuild it from the files.')
            raise BagError(msg) from exc
        self._reader = reader
        files = sorted(path.glob('*.db3*')) + self.files if path.is_dir() else [path]
        self.storage = 'sqlite3' if any('.db3' in f.name for f in files) else 'mcap'
        self.files = files
        self.start_ns = reader.start_time if reader.message_count else 0
        # rosbags reports end = last timestamp + 1 ns
        self.end_ns = reader.end_time - 1 if reader.message_count else 0
        self.message_count = reader.message_count
        counts: dict[str, int] = {}
        for conn in reader.connections:
            counts[conn.topic] = counts.get(conn.topic, 0) + conn.msgcount
        for conn in reader.connections:
            if conn.topic in self.topics:
                continue
            qos = getattr(conn.ext, 'offered_qos_profiles', [])
            self.topics[conn.topic] = TopicInfo(
                conn.topic, conn.msgtype, counts[conn.topic], parse_offered_qos(
                    [_rosbags_qos(q) for q in qos]), conn.digest or '',
                conn.msgdef.data if conn.msgdef else '',
                getattr(conn.ext, 'serialization_format', 'cdr'))

    def _open_scan(self, files: list[Path], unfinished: list[Path], has_metadata: bool) -> None:
        self.storage = 'mcap'
        self.complete = not unfinished
        self._scan_files = files
        names = ', '.join(p.name for p in unfinished)
        if unfinished:
            self.notes.append(f'The file(s) {names} were not closed (the recorder was killed or '
                              'the disk was full); their complete records were recovered.')
        metadata = None
        if has_metadata:
            try:
                metadata = load_metadata(self.path)
            except BagError:
                metadata = None
        start, end = 2**63 - 1, 0
        for path in files:
            contents = read_mcap_contents(path)
            for damage in contents.damaged:
                self.notes.append(f'{path.name}: a {damage}; it was skipped.')
            if contents.stopped_at:
                self.notes.append(
                    f'{path.name}: reading stopped because the {contents.stopped_at}.')
            schemas = {}
            for channel in contents.channels.values():
                topic = self.topics.get(channel.topic)
                if topic is None:
                    topic = self.topics[channel.topic] = TopicInfo(
                        channel.topic, channel.schema_name, 0,
                        parse_offered_qos(channel.metadata.get('offered_qos_profiles')),
                        channel.metadata.get('topic_type_hash', ''),
                        channel.schema_data.decode('utf-8', 'replace'),
                        channel.message_encoding)
                topic.message_count += contents.channel_counts.get(channel.id, 0)
                schemas[channel.id] = channel
            if contents.message_count:
                start = min(start, contents.start_ns)
                end = max(end, contents.end_ns)
            self.message_count += contents.message_count
        if self.message_count:
            self.start_ns, self.end_ns = start, end
        if metadata is None and self.path.is_dir():
            self.notes.append(f'metadata.yaml is missing; run `mindgrasp bag reindex {self.path}` '
                              'to write it.')

    def rebuild_metadata(self) -> Path:
        """Write metadata.yaml from the MCAP files (for bags opened by a scan)."""
        rebuild_metadata(self.path)
        return self.path / METADATA_FILE

    def messages(self, topics: Iterable[str] | None = None,
                 start_ns: int | None = None) -> Iterator[tuple[str, int, bytes]]:
        """``(topic, timestamp_ns, cdr_bytes)`` in time order (file order for recovered files).

        Args:
            topics: Only these topics (default: all).
            start_ns: Only messages at or after this bag time (ns).
        """
        wanted = None if topics is None else set(topics)
        if self._reader is not None:
            conns = [c for c in self._reader.connections if wanted is None or c.topic in wanted]
            if not conns:
                return
            last: int | None = None
            at_last: set[tuple[str, int, bytes]] = set()   # yielded at time ``last``
            try:
                for conn, timestamp, data in self._reader.messages(conns, start=start_ns):
                    if timestamp != last:
                        last, at_last = timestamp, set()
                    at_last.add(_key(conn.topic, data))
                    yield conn.topic, timestamp, data
            except (ReaderError, *CORRUPT_RECORD_ERRORS) as exc:
                mcap = [f for f in self.files if f.suffix == '.mcap']
                if not mcap:
                    msg = (f'The bag {self.path} is corrupt: {exc} Messages up to this point '
                           'were read; the rest cannot be.')
                    raise BagError(msg) from exc
                # read what can be read: the rest comes from a scan, which skips damaged records
                self.notes.append(f'A damaged record stopped the indexed reader ({exc}); the '
                                  'messages after it were read by a scan that skips it.')
                for topic, timestamp, data in self._scan(mcap, wanted, start_ns):
                    if last is not None and (timestamp < last or (timestamp == last
                                             and _key(topic, data) in at_last)):
                        continue
                    yield topic, timestamp, data
            return
        if not self._scan_files:
            msg = f'The bag {self.path} is not open; call open() first.'
            raise BagError(msg)
        yield from self._scan(self._scan_files, wanted, start_ns)

    @staticmethod
    def _scan(files: list[Path], wanted: set[str] | None,
              start_ns: int | None) -> Iterator[tuple[str, int, bytes]]:
        """Every readable message of ``files`` in file order (damaged records skipped)."""
        for channel, timestamp, data in itertools.chain.from_iterable(
                iter_mcap_messages(p) for p in files):
            if wanted is not None and channel.topic not in wanted:
                continue
            if start_ns is not None and timestamp < start_ns:
                continue
            yield channel.topic, timestamp, data

    def close(self) -> None:
        """Release the files."""
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        self._scan_files = []

    def __enter__(self) -> BagReader:
        return self.open()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def _key(topic: str, data: bytes | memoryview) -> tuple[str, int, bytes]:
    """Tells apart messages of one timestamp, cheaply (no hash of a whole image)."""
    return topic, len(data), bytes(data[:64])


def _rosbags_qos(qos: Any) -> dict[str, Any]:
    """rosbags ``Qos`` named tuple -> dict accepted by :func:`parse_offered_qos`."""
    if isinstance(qos, dict):
        return qos
    return {
        'history': qos.history.name.lower(), 'depth': qos.depth,
        'reliability': qos.reliability.name.lower(), 'durability': qos.durability.name.lower(),
        'deadline': {'sec': qos.deadline.sec, 'nsec': qos.deadline.nsec},
        'lifespan': {'sec': qos.lifespan.sec, 'nsec': qos.lifespan.nsec},
        'liveliness': qos.liveliness.name.lower(),
        'liveliness_lease_duration': {'sec': qos.liveliness_lease_duration.sec,
                                      'nsec': qos.liveliness_lease_duration.nsec},
        'avoid_ros_namespace_conventions': qos.avoid_ros_namespace_conventions}
