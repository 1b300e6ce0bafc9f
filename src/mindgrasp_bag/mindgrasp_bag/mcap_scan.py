"""Read MCAP files, finished or not (a recorder killed with SIGKILL leaves no summary).

Finished files are read through their summary with the ``mcap`` library. For unfinished ones the
``mcap`` library's ``StreamReader`` cannot be used as is: its reads do not check for short reads,
so a record cut off at the end of the file is parsed from garbage instead of being reported. This
module therefore does the record framing itself (opcode + length, checked against the file size)
and hands every complete record to the ``mcap`` library for parsing; the scan stops at the first
incomplete or corrupt record, so everything before it is recovered.
"""

from __future__ import annotations

import contextlib
import importlib
import io
import struct
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Channel, Chunk, Footer, Message, Schema, Statistics
from mcap.stream_reader import StreamReader

from mindgrasp_common.safe_files import write_atomic

from .errors import BagError


def _zstd_errors() -> tuple[type[Exception], ...]:
    """The ZstdError classes of the zstd bindings mcap (zstandard) and rosbags (backports.zstd,
    compression.zstd from Python 3.14) decompress with."""
    errors: list[type[Exception]] = []
    for module in ('zstandard', 'backports.zstd', 'compression.zstd'):
        with contextlib.suppress(ImportError):
            errors.append(importlib.import_module(module).ZstdError)
    return tuple(errors)


#: what reading a damaged record raises: a failed CRC or framing (mcap), bad bytes, or a chunk
#: whose compressed data no longer decompresses (a ZstdError; lz4.frame's RuntimeError)
CORRUPT_RECORD_ERRORS = (McapError, ValueError, struct.error, UnicodeDecodeError, EOFError,
                         RuntimeError, *_zstd_errors())

__all__ = ['ChannelInfo', 'McapContents', 'damage_sentences', 'is_finished', 'iter_mcap_messages',
           'read_mcap_contents', 'recover_mcap', 'verify_mcap']

MAGIC = b'\x89MCAP0\r\n'
_RECORD_HEADER = struct.Struct('<BQ')


@dataclass
class ChannelInfo:
    """An MCAP channel with its schema (``schema_data`` is the message definition text)."""

    id: int
    topic: str
    message_encoding: str
    metadata: dict[str, str]
    schema_name: str = ''
    schema_encoding: str = ''
    schema_data: bytes = b''


@dataclass
class McapContents:
    """What an MCAP file holds: channels, per-channel counts and the time range (ns)."""

    path: Path
    channels: dict[int, ChannelInfo] = field(default_factory=dict)
    channel_counts: dict[int, int] = field(default_factory=dict)
    message_count: int = 0
    start_ns: int = 0
    end_ns: int = 0
    complete: bool = True        # False: no summary (writer killed), contents from a scan
    stopped_at: str = ''         # why a scan stopped before the end of the file
    damaged: list[str] = field(default_factory=list)  # corrupt records skipped by a scan
    compression: str = ''
    #: per skipped record: (last message time before it, first after it) in ns; None at an end
    gaps: list[tuple[int | None, int | None]] = field(default_factory=list)
    footer: bool = False         # a scan reached the footer
    last_ns: int | None = None   # log time of the last readable message in file order (scan)


def _check_magic(path: Path, head: bytes) -> None:
    if head[:8] != MAGIC:
        msg = (f'{path} is not an MCAP file (bad magic bytes); pass a rosbag2 directory or an '
               '.mcap file written by ros2 bag, rosbags or mindgrasp bag record.')
        raise BagError(msg)


def _is_finished(f: io.BufferedReader, size: int) -> bool:
    if size < 16 + 37:
        return False
    f.seek(size - 8)
    return f.read(8) == MAGIC


def _channel_info(channel: Channel, schemas: dict[int, Schema]) -> ChannelInfo:
    schema = schemas.get(channel.schema_id)
    return ChannelInfo(channel.id, channel.topic, channel.message_encoding,
                       dict(channel.metadata),
                       schema.name if schema else '', schema.encoding if schema else '',
                       bytes(schema.data) if schema else b'')


def _records(path: Path, f: io.BufferedReader, size: int,
             contents: McapContents) -> Iterator[object]:
    """Every complete top-level record, chunks broken up into their records."""
    f.seek(8)
    offset = 8
    while offset + _RECORD_HEADER.size <= size:
        head = f.read(_RECORD_HEADER.size)
        opcode, length = _RECORD_HEADER.unpack(head)
        start, end = offset, offset + _RECORD_HEADER.size + length
        if not (0x01 <= opcode <= 0x10 or opcode >= 0x80):
            contents.stopped_at = (f'bytes at {start} are not an MCAP record (opcode '
                                   f'0x{opcode:02x}): the file is corrupt from there')
            return
        if end > size:
            contents.stopped_at = (f'record at byte {start} is cut off at the end of the file '
                                   f'({end - size} bytes missing)' if end - size < size else
                                   f'record at byte {start} has an impossible length '
                                   f'({length} bytes): the file is corrupt from there')
            return
        body = f.read(length)
        offset = end
        reader = StreamReader(io.BytesIO(head + body), skip_magic=True, validate_crcs=True)
        records = reader.records
        try:
            while True:
                yield next(records)
        except (EndOfFile, StopIteration):
            pass
        except CORRUPT_RECORD_ERRORS as exc:
            # framing intact, content not (a flipped bit fails the chunk CRC): skip this record,
            # the ones after it are still readable
            contents.damaged.append(f'record at byte {start} (opcode 0x{opcode:02x}, '
                                    f'{length} bytes) is corrupt ({exc})')
            continue
        if opcode == 0x02:  # footer: nothing of interest follows
            return


def read_mcap_contents(path: Path, *, scan: bool = False) -> McapContents:
    """Channels, counts and time range of one MCAP file: its summary, else a scan.

    Args:
        path: The .mcap file.
        scan: Read every record even when the file has a summary (finds what a summary hides:
            chunks whose CRC fails, records cut off); the counts are then what is readable.

    Raises:
        BagError: the file does not exist or is not MCAP.
    """
    path = Path(path)
    contents = McapContents(path)
    try:
        f = path.open('rb')
    except OSError as exc:
        msg = f'Cannot open {path}: {exc.strerror}; check the path and its permissions.'
        raise BagError(msg) from None
    with f:
        size = path.stat().st_size
        _check_magic(path, f.read(8))
        if not scan and _is_finished(f, size):
            f.seek(0)
            try:
                summary = make_reader(f).get_summary()
            except CORRUPT_RECORD_ERRORS:
                summary = None
            if summary is not None and summary.statistics is not None:
                stats: Statistics = summary.statistics
                contents.channels = {cid: _channel_info(ch, summary.schemas)
                                     for cid, ch in summary.channels.items()}
                contents.channel_counts = dict(stats.channel_message_counts)
                contents.message_count = stats.message_count
                if stats.message_count:
                    contents.start_ns = stats.message_start_time
                    contents.end_ns = stats.message_end_time
                contents.compression = next(
                    (c.compression for c in summary.chunk_indexes if c.compression), '')
                contents.footer = True
                return contents
        contents.complete = False
        schemas: dict[int, Schema] = {}
        counts: dict[int, int] = defaultdict(int)
        start, end = 2**63 - 1, 0
        open_gaps = 0
        for record in _records(path, f, size, contents):
            for _ in range(len(contents.damaged) - len(contents.gaps)):
                contents.gaps.append((contents.last_ns, None))   # closed by the next message
                open_gaps += 1
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                contents.channels[record.id] = _channel_info(record, schemas)
            elif isinstance(record, Message):
                counts[record.channel_id] += 1
                start = min(start, record.log_time)
                end = max(end, record.log_time)
                contents.last_ns = record.log_time
                while open_gaps:
                    k = len(contents.gaps) - open_gaps
                    contents.gaps[k] = (contents.gaps[k][0], record.log_time)
                    open_gaps -= 1
            elif isinstance(record, Chunk) and record.compression:
                contents.compression = record.compression
            elif isinstance(record, Footer):
                contents.complete = contents.footer = True
        for _ in range(len(contents.damaged) - len(contents.gaps)):
            contents.gaps.append((contents.last_ns, None))
        contents.channel_counts = dict(counts)
        contents.message_count = sum(counts.values())
        if contents.message_count:
            contents.start_ns, contents.end_ns = start, end
    return contents


def iter_mcap_messages(path: Path) -> Iterator[tuple[ChannelInfo, int, bytes]]:
    """``(channel, log_time_ns, data)`` for every readable message, in file order.

    Works on unfinished files (stops at the first incomplete record).
    """
    path = Path(path)
    contents = McapContents(path)
    with path.open('rb') as f:
        size = path.stat().st_size
        _check_magic(path, f.read(8))
        schemas: dict[int, Schema] = {}
        channels: dict[int, ChannelInfo] = {}
        for record in _records(path, f, size, contents):
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = _channel_info(record, schemas)
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is not None:
                    yield channel, record.log_time, bytes(record.data)


def is_finished(path: Path) -> bool:
    """True when an MCAP file ends with its closing magic (its writer finished it)."""
    try:
        size = Path(path).stat().st_size
        with Path(path).open('rb') as f:
            return _is_finished(f, size)
    except OSError:
        return False


def recover_mcap(path: Path) -> int:
    """Rewrite an unfinished MCAP file as a finished one (summary, footer); returns messages kept.

    Every complete record is copied (schemas, channels, messages with both times); the cut-off
    tail, which no reader can use, is left out. The new file replaces the old one atomically, so
    other tools (rosbags, ros2 bag, Foxglove) can open the bag afterwards.
    """
    from mcap.writer import CompressionType
    from mcap.writer import Writer as McapWriter

    path = Path(path)
    contents = McapContents(path)
    counted = [0]

    def rewrite(tmp: Path) -> None:
        with path.open('rb') as f, tmp.open('wb') as out:
            size = path.stat().st_size
            _check_magic(path, f.read(8))
            writer = McapWriter(out, compression=CompressionType.NONE)
            writer.start(profile='ros2', library='mindgrasp-ros bag recovery (mcap python)')
            schema_ids: dict[int, int] = {}
            channel_ids: dict[int, int] = {}
            for record in _records(path, f, size, contents):
                if isinstance(record, Schema) and record.id not in schema_ids:
                    schema_ids[record.id] = writer.register_schema(record.name, record.encoding,
                                                                   record.data)
                elif isinstance(record, Channel) and record.id not in channel_ids:
                    channel_ids[record.id] = writer.register_channel(
                        record.topic, record.message_encoding,
                        schema_ids.get(record.schema_id, 0), dict(record.metadata))
                elif isinstance(record, Message) and record.channel_id in channel_ids:
                    writer.add_message(channel_ids[record.channel_id], record.log_time,
                                       record.data, record.publish_time, record.sequence)
                    counted[0] += 1
            writer.finish()

    # a full disk leaves the original file as it was and no partial copy beside it
    write_atomic(path, rewrite)
    return counted[0]


def verify_mcap(path: Path) -> list[str]:
    """Damage found by reading every record of an MCAP file, as sentences with byte offsets.

    Checks what a summary-based reader never looks at: every record's framing, every chunk's CRC
    (bit flips), and that the file ends with its footer and closing magic. [] when sound.
    """
    path = Path(path)
    try:
        contents = read_mcap_contents(path, scan=True)
    except BagError:
        return [f'{path.name}: not an MCAP file (bad magic bytes at byte 0).']
    return damage_sentences(contents)


def damage_sentences(contents: McapContents) -> list[str]:
    """What a scan (:func:`read_mcap_contents` with ``scan=True``) found wrong, as sentences."""
    name = contents.path.name
    problems = [f'{name}: {d}; it was skipped.' for d in contents.damaged]
    if contents.stopped_at:
        problems.append(f'{name}: {contents.stopped_at}; the records before it are '
                        'readable (`mindgrasp bag reindex` keeps them).')
    elif not contents.footer:
        size = contents.path.stat().st_size
        problems.append(f'{name}: ends at byte {size} without a footer (the recorder was '
                        'killed); run `mindgrasp bag reindex` to finish it.')
    return problems
