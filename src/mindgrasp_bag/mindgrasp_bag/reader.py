"""Read any rosbag2 bag: ours, ``ros2 bag`` (sqlite3 or MCAP), rosbags; finished or not,
sound or damaged.

MCAP bags are read by :mod:`.mcap_scan`: a file with an intact summary through its chunk index
(in time order, a damaged chunk skipped and said in ``notes``), a file without one (a recorder
killed, a disk full, a file cut short, a damaged summary) by a scan that skips damage and reads
every intact chunk after it. A damaged chunk thus costs only its own messages, in every tool that
reads bags through this class (info, play, replay, export, training, latency). sqlite3 bags and
whole-file compressed ones are read with ``rosbags.rosbag2.Reader``.
"""

from __future__ import annotations

import contextlib
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
    McapContents,
    iter_indexed_messages,
    iter_scanned_messages,
    read_mcap_contents,
)
from .metadata import DAMAGED_SUFFIX, METADATA_FILE, load_metadata, mcap_files, rebuild_metadata
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
        self._reader: Reader | None = None
        self._reset()

    def _reset(self) -> None:
        """Nothing read yet (also when opened again)."""
        self.topics: dict[str, TopicInfo] = {}
        self.start_ns = 0
        self.end_ns = 0
        self.message_count = 0
        self.storage = ''
        self.files: list[Path] = []
        self.notes: list[str] = []
        self.complete = True
        self._contents: list[McapContents] = []

    @property
    def duration_ns(self) -> int:
        """Time between the first and the last message (ns)."""
        return max(0, self.end_ns - self.start_ns)

    def open(self) -> BagReader:
        """Read the bag's metadata (and the files' summaries).

        Raises:
            BagError: missing path, not a bag, or a corrupt bag; the message says what to do.
        """
        self.close()
        self._reset()                       # opened again: counted afresh
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
            if self.files:
                # MCAP: our own reader, which loses only damaged chunks (rosbags stops at the
                # first one); rosbags reads sqlite3 bags and whole-file compressed ones
                self._open_mcap(self.files, has_metadata)
            else:
                self._open_rosbags(self.path)
        elif self.path.suffix == '.mcap':
            self.files = [self.path]
            self._open_mcap(self.files, False)
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

    def _open_mcap(self, files: list[Path], has_metadata: bool) -> None:
        """Topics, counts and times from each file's summary (a scan where it has none)."""
        self.storage = 'mcap'
        self._contents = [read_mcap_contents(path) for path in files]
        unfinished = [c.path.name for c in self._contents if not c.footer]
        self.complete = not unfinished
        if unfinished:
            self.notes.append(f'The file(s) {", ".join(unfinished)} were not closed (the recorder '
                              'was killed or the disk was full); their complete records were '
                              'recovered.')
        declared: dict[str, dict[str, Any]] = {}
        if has_metadata:
            try:
                metadata = load_metadata(self.path)
            except BagError as exc:   # corrupt, not missing: the files are read all the same
                self.notes.append(f'{exc} The .mcap files were read without it.')
            else:
                for entry in metadata.get('topics_with_message_count') or []:
                    topic = (entry or {}).get('topic_metadata') if isinstance(entry, dict) else None
                    if isinstance(topic, dict) and topic.get('name'):
                        declared[str(topic['name'])] = topic
        elif self.path.is_dir():
            self.notes.append(f'metadata.yaml is missing; run `mindgrasp bag reindex {self.path}` '
                              'to write it.')
        start, end = 2**63 - 1, 0
        for contents in self._contents:
            name = contents.path.name
            for damage in contents.damaged:
                self.notes.append(f'{name}: a {damage}; it was skipped.')
            if contents.stopped_at:
                self.notes.append(f'{name}: reading stopped because the {contents.stopped_at}.')
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
                # what metadata.yaml says of the topic fills what the channel lacks (rosbags and
                # older rosbag2 put the type hash and QoS there only)
                meta = declared.get(channel.topic, {})
                topic.type_description_hash = (topic.type_description_hash
                                               or str(meta.get('type_description_hash') or ''))
                if not topic.offered_qos_profiles and meta.get('offered_qos_profiles'):
                    with contextlib.suppress(*CORRUPT_RECORD_ERRORS, TypeError):
                        topic.offered_qos_profiles = parse_offered_qos(
                            meta['offered_qos_profiles'])
            if contents.message_count:
                start = min(start, contents.start_ns)
                end = max(end, contents.end_ns)
            self.message_count += contents.message_count
        if self.message_count:
            self.start_ns, self.end_ns = start, end
        if self.path.is_dir():
            backups = sorted(p.name for p in self.path.glob(f'*{DAMAGED_SUFFIX}*'))
            if backups:
                self.notes.append(f'{", ".join(backups)}: the original(s) of the files `mindgrasp '
                                  'bag reindex` repaired, kept as they were; delete them once the '
                                  'repaired bag has what you need.')

    def rebuild_metadata(self) -> Path:
        """Write metadata.yaml from the MCAP files (for bags opened by a scan)."""
        rebuild_metadata(self.path)
        return self.path / METADATA_FILE

    def messages(self, topics: Iterable[str] | None = None,
                 start_ns: int | None = None) -> Iterator[tuple[str, int, bytes]]:
        """``(topic, timestamp_ns, cdr_bytes)`` in time order (file order for unfinished files).

        Damaged chunks are skipped (each one said in ``notes``); every other message is read.

        Args:
            topics: Only these topics (default: all).
            start_ns: Only messages at or after this bag time (ns).
        """
        for topic, timestamp, _, data in self.records(topics, start_ns):
            yield topic, timestamp, data

    def records(self, topics: Iterable[str] | None = None,
                start_ns: int | None = None) -> Iterator[tuple[str, int, int, bytes]]:
        """As :meth:`messages`, with the publication time: ``(topic, log_time_ns,
        publish_time_ns, cdr_bytes)`` (``publish_time`` is the log time when the bag has none).
        """
        wanted = None if topics is None else set(topics)
        if self._reader is not None:
            conns = [c for c in self._reader.connections if wanted is None or c.topic in wanted]
            if not conns:
                return
            try:
                for conn, timestamp, data in self._reader.messages(conns, start=start_ns):
                    yield conn.topic, timestamp, timestamp, data
            except (ReaderError, *CORRUPT_RECORD_ERRORS) as exc:
                msg = (f'The bag {self.path} is corrupt: {exc} Messages up to this point '
                       'were read; the rest cannot be.')
                raise BagError(msg) from exc
            return
        if not self._contents:
            msg = f'The bag {self.path} is not open; call open() first.'
            raise BagError(msg)
        for contents in self._contents:
            ids = None if wanted is None else {
                cid for cid, ch in contents.channels.items() if ch.topic in wanted}
            if ids is not None and not ids:
                continue
            if contents.indexed:
                source = iter_indexed_messages(contents, channel_ids=ids, start_ns=start_ns,
                                               on_skip=self._skipped)
            else:
                source = iter_scanned_messages(contents.path, channel_ids=ids)
            for m in source:
                if wanted is not None and m.channel.topic not in wanted:
                    continue
                if start_ns is not None and m.log_time < start_ns:
                    continue
                yield m.channel.topic, m.log_time, m.publish_time or m.log_time, m.data

    def _skipped(self, sentence: str) -> None:
        if sentence not in self.notes:
            self.notes.append(sentence)

    def close(self) -> None:
        """Release the files."""
        if self._reader is not None:
            self._reader.close()
            self._reader = None
        self._contents = []

    def __enter__(self) -> BagReader:
        return self.open()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


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
