"""Read MCAP files, finished or not, sound or damaged: a damaged chunk costs only that chunk.

MCAP chunks are independent (each carries its records and the CRC of its uncompressed bytes), so
a reader can lose exactly the chunks that are damaged and read every other one. Two ways, as the
official ``mcap`` CLI (``mcap doctor`` / ``mcap recover``):

- **indexed** (:func:`iter_indexed_messages`): a finished file whose summary is intact (its
  CRC in the footer matches) lists every chunk with its offset; each chunk is read at its offset
  and checked (framing, CRC, decompression). A chunk that fails is skipped and counted with the
  number of messages its message index records say it held.
- **scan** (:func:`read_mcap_contents` with ``scan=True``, :func:`iter_mcap_messages`): record
  by record from the start, for files without a summary (a recorder killed with SIGKILL, a disk
  full, a file cut short) and to find what a summary hides. A record whose framing is broken
  (garbage opcode, impossible length) is not the end of the file: the scan looks forward for the
  next record that frames a chunk whose CRC matches (or the data end record) and goes on from
  there, counting the bytes it skipped. Only a file that has no intact chunk after the damage
  stops there (cut off, or garbage to the end).

The ``mcap`` library's ``StreamReader`` is not used for the framing: its reads do not check for
short reads, so a record cut off at the end of the file would be parsed from garbage. Records are
framed here (opcode + length, checked against the file size) and handed to the ``mcap`` library
for parsing (``breakup_chunk`` with CRC validation, the record classes' ``read``).
"""

from __future__ import annotations

import contextlib
import heapq
import importlib
import io
import mmap
import struct
import zlib
from collections import defaultdict
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Channel, Chunk, ChunkIndex, Footer, Message, Schema, Statistics
from mcap.stream_reader import CRCValidationError, StreamReader, breakup_chunk

try:            # the decompressors the mcap library uses
    import zstandard
except ImportError:     # pragma: no cover - a dependency of mcap[zstd]
    zstandard = None
try:
    import lz4.frame
except ImportError:     # pragma: no cover
    lz4 = None

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
                         RuntimeError, KeyError, MemoryError, OverflowError, *_zstd_errors())

__all__ = ['ChannelInfo', 'McapContents', 'McapMessage', 'damage_sentences', 'is_finished',
           'iter_indexed_messages', 'iter_mcap_messages', 'iter_scanned_messages',
           'read_mcap_contents', 'recover_mcap', 'verify_mcap']

MAGIC = b'\x89MCAP0\r\n'
_RECORD_HEADER = struct.Struct('<BQ')
# chunk record after its opcode and length: message start, end (ns), uncompressed size, CRC,
# length of the compression name
_CHUNK_HEAD = struct.Struct('<QQQII')
_U64 = struct.Struct('<Q')
_COMPRESSIONS = (b'', b'zstd', b'lz4')
# a data end record (opcode 0x0f, length 4): where the summary section starts
_DATA_END_HEAD = _RECORD_HEADER.pack(0x0F, 4)
_FOOTER_SIZE = 9 + 8 + 8 + 4
_OPCODE_CHUNK, _OPCODE_MESSAGE_INDEX = 0x06, 0x07


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
class McapMessage:
    """One message as read from a file (times in ns)."""

    channel: ChannelInfo
    log_time: int
    publish_time: int
    data: bytes


@dataclass
class McapContents:
    """What an MCAP file holds: channels, per-channel counts and the time range (ns).

    From the summary when it is intact (``indexed``), else from a scan of every record (the
    counts are then what is readable).
    """

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
    #: chunks a scan skipped (CRC, decompression or framing failed) and the bytes it skipped
    skipped_chunks: int = 0
    skipped_bytes: int = 0
    #: messages known to be lost: counted from the message index records of skipped chunks
    lost_known: int = 0
    #: the summary's chunk indexes when the summary is intact (the file can be read indexed)
    chunk_indexes: list[ChunkIndex] | None = None
    indexed: bool = False


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


@contextlib.contextmanager
def _mapped(path: Path) -> Iterator[tuple[BinaryIO, bytes | mmap.mmap, int]]:
    """The open file, its bytes (memory-mapped: nothing is read until used) and its size."""
    try:
        f = path.open('rb')
    except OSError as exc:
        msg = f'Cannot open {path}: {exc.strerror}; check the path and its permissions.'
        raise BagError(msg) from None
    with f:
        size = path.stat().st_size
        _check_magic(path, f.read(8))
        buf = mmap.mmap(f.fileno(), size, access=mmap.ACCESS_READ)
        try:
            yield f, buf, size
        finally:
            buf.close()


# -- chunks -------------------------------------------------------------------------------------
def _chunk_at(buf: bytes | mmap.mmap, offset: int, size: int, *, strict: bool) -> Chunk | None:
    """The chunk record framed at ``offset``, or None when the bytes there do not frame one.

    ``strict`` (looking for a chunk in garbage): the data must end exactly where the record
    does, as every MCAP writer writes it, so random bytes almost never pass.
    """
    if offset + 9 + _CHUNK_HEAD.size > size:
        return None
    opcode, length = _RECORD_HEADER.unpack_from(buf, offset)
    end = offset + 9 + length
    if opcode != _OPCODE_CHUNK or end > size:
        return None
    start_ns, end_ns, usize, crc, clen = _CHUNK_HEAD.unpack_from(buf, offset + 9)
    p = offset + 9 + _CHUNK_HEAD.size
    if clen > 8 or p + clen + 8 > end:
        return None
    compression = bytes(buf[p:p + clen])
    if compression not in _COMPRESSIONS:
        return None
    (dlen,) = _U64.unpack_from(buf, p + clen)
    p += clen + 8
    if p + dlen > end or (strict and (p + dlen != end or start_ns > end_ns
                                      or (not compression and usize != dlen))):
        return None
    return Chunk(compression=compression.decode(), data=bytes(buf[p:p + dlen]),
                 message_start_time=start_ns, message_end_time=end_ns,
                 uncompressed_crc=crc, uncompressed_size=usize)


_MESSAGE_HEAD = struct.Struct('<HIQQ')   # channel id, sequence, log time, publish time


def _chunk_bytes(chunk: Chunk) -> bytes:
    """The chunk's records, decompressed, their CRC checked (when written)."""
    if chunk.compression == 'zstd':
        data = zstandard.decompress(chunk.data, chunk.uncompressed_size)
    elif chunk.compression == 'lz4':
        data = lz4.frame.decompress(chunk.data)
    else:
        data = chunk.data
    if len(data) != chunk.uncompressed_size:
        msg = (f'the chunk holds {len(data)} bytes once decompressed, its header says '
               f'{chunk.uncompressed_size}')
        raise McapError(msg)
    if chunk.uncompressed_crc:
        crc = zlib.crc32(data)
        if crc != chunk.uncompressed_crc:
            raise CRCValidationError(chunk.uncompressed_crc, crc, chunk)
    return data


def _chunk_records(chunk: Chunk) -> list[object]:
    """The chunk's records, its CRC checked (raises one of CORRUPT_RECORD_ERRORS).

    Messages are framed here with ``struct`` (the bulk of every chunk, several times faster
    than the ``mcap`` library's stream reader); schemas and channels by the ``mcap`` library.
    """
    data = _chunk_bytes(chunk)
    records: list[object] = []
    p, size = 0, len(data)
    unpack_head, unpack_message = _RECORD_HEADER.unpack_from, _MESSAGE_HEAD.unpack_from
    while p < size:
        opcode, length = unpack_head(data, p)
        start, p = p + 9, p + 9 + length
        if p > size:
            msg = f'a record in the chunk runs past its end ({p} > {size} bytes)'
            raise McapError(msg)
        if opcode == 0x05:
            channel_id, sequence, log_time, publish_time = unpack_message(data, start)
            records.append(Message(channel_id=channel_id, sequence=sequence, log_time=log_time,
                                   publish_time=publish_time, data=data[start + 22:p]))
        elif opcode in (0x03, 0x04):
            records += breakup_chunk(Chunk(compression='', data=data[start - 9:p],
                                           message_start_time=0, message_end_time=0,
                                           uncompressed_crc=0, uncompressed_size=p - start + 9))
    return records


def _is_intact_chunk(buf: bytes | mmap.mmap, offset: int, size: int) -> bool:
    chunk = _chunk_at(buf, offset, size, strict=True)
    if chunk is None:
        return False
    try:
        if chunk.uncompressed_crc:
            _chunk_bytes(chunk)
        else:               # no CRC written: its records must parse
            _chunk_records(chunk)
    except CORRUPT_RECORD_ERRORS:
        return False
    return True


def _resync(buf: bytes | mmap.mmap, start: int, size: int) -> int | None:
    """Offset of the first intact chunk record (or the data end record) at or after ``start``;
    None when there is none (the file is cut off or garbage to its end)."""
    data_end = buf.find(_DATA_END_HEAD, start, size)
    limit = data_end if data_end >= 0 else size
    pos = start
    while True:
        pos = buf.find(b'\x06', pos, limit)
        if pos < 0:
            return data_end if data_end >= 0 else None
        if _is_intact_chunk(buf, pos, size):
            return pos
        pos += 1


def _message_index_count(buf: bytes | mmap.mmap, offset: int, size: int, *,
                         records: int | None = None) -> int | None:
    """Messages listed by the message index records at ``offset`` (those that follow a chunk;
    at most ``records`` of them); None when there are none or they are damaged too."""
    total, seen = 0, 0
    while offset + 9 + 6 <= size and (records is None or seen < records):
        opcode, length = _RECORD_HEADER.unpack_from(buf, offset)
        if opcode != _OPCODE_MESSAGE_INDEX or offset + 9 + length > size or length < 6:
            break
        n_bytes = struct.unpack_from('<I', buf, offset + 9 + 2)[0]
        if 6 + n_bytes != length or n_bytes % 16:
            return None
        total += n_bytes // 16
        seen += 1
        offset += 9 + length
    return total if seen else None


def _chunk_index_count(buf: bytes | mmap.mmap, index: ChunkIndex, size: int) -> int | None:
    """Messages of an indexed chunk, from its message index records (None when unreadable)."""
    if not index.message_index_offsets:
        return 0
    total = 0
    for offset in index.message_index_offsets.values():
        count = _message_index_count(buf, offset, size, records=1)
        if count is None:
            return None
        total += count
    return total


def _lost(count: int | None) -> str:
    return 'its message count is unknown' if count is None else f'{count} message(s) lost'


# -- the scan -----------------------------------------------------------------------------------
def _records(path: Path, buf: bytes | mmap.mmap, size: int,
             contents: McapContents) -> Iterator[object]:
    """Every readable top-level record, chunks broken up into their records.

    Damage is skipped and described in ``contents.damaged`` (one sentence per damaged stretch);
    a file with nothing intact after its damage ends the scan (``contents.stopped_at``).
    """
    offset = 8
    while offset + _RECORD_HEADER.size <= size:
        opcode, length = _RECORD_HEADER.unpack_from(buf, offset)
        start, end = offset, offset + _RECORD_HEADER.size + length
        if not (0x01 <= opcode <= 0x0F or opcode >= 0x80) or end > size:
            resume = _resync(buf, start + 1, size)
            if resume is None:
                if not (0x01 <= opcode <= 0x0F or opcode >= 0x80):
                    contents.stopped_at = (f'bytes at {start} are not an MCAP record (opcode '
                                           f'0x{opcode:02x}): the file is corrupt from there')
                elif end - size < size:
                    contents.stopped_at = (f'record at byte {start} is cut off at the end of '
                                           f'the file ({end - size} bytes missing)')
                else:
                    contents.stopped_at = (f'record at byte {start} has an impossible length '
                                           f'({length} bytes): the file is corrupt from there')
                return
            what = (f'opcode 0x{opcode:02x}' if not (0x01 <= opcode <= 0x0F or opcode >= 0x80)
                    else f'a record of {length} bytes in a file of {size}')
            contents.damaged.append(f'bytes {start}-{resume} ({resume - start} bytes) are not '
                                    f'MCAP records ({what}); reading went on at the next intact '
                                    f'record, at byte {resume}')
            contents.skipped_bytes += resume - start
            contents.skipped_chunks += 1
            offset = resume
            continue
        offset = end
        if opcode == _OPCODE_CHUNK:
            chunk = _chunk_at(buf, start, size, strict=False)
            try:
                if chunk is None:
                    msg = 'its header does not frame a chunk'
                    raise McapError(msg)
                records = _chunk_records(chunk)
            except CORRUPT_RECORD_ERRORS as exc:
                # framing intact, content not (a flipped bit fails the chunk CRC): skip this
                # chunk, the ones after it are still readable
                count = _message_index_count(buf, end, size)
                contents.damaged.append(f'record at byte {start} (opcode 0x06, {length} bytes) '
                                        f'is corrupt ({exc}; {_lost(count)})')
                contents.skipped_chunks += 1
                contents.skipped_bytes += end - start
                contents.lost_known += count or 0
                continue
            if chunk.compression:
                contents.compression = chunk.compression
            yield from records
            continue
        if opcode == _OPCODE_MESSAGE_INDEX or opcode >= 0x80:
            continue                        # not needed to read messages
        try:
            records = _parse_record(bytes(buf[start:end]))
        except CORRUPT_RECORD_ERRORS as exc:
            contents.damaged.append(f'record at byte {start} (opcode 0x{opcode:02x}, '
                                    f'{length} bytes) is corrupt ({exc})')
            contents.skipped_bytes += end - start
            continue
        yield from records
        if opcode == 0x02:  # footer: nothing of interest follows
            return


def _parse_record(record: bytes) -> list[object]:
    """The record (opcode, length, body) parsed by the ``mcap`` library."""
    out = []
    records = StreamReader(io.BytesIO(record), skip_magic=True).records
    try:
        while True:
            out.append(next(records))
    except (EndOfFile, StopIteration):
        pass
    return out


def _summary(path: Path, f: io.BufferedReader, buf: bytes | mmap.mmap,
             size: int) -> object | None:
    """The file's summary when it is intact (its CRC, when written, matches), else None."""
    if size < 8 + _FOOTER_SIZE + 8:
        return None
    footer_at = size - 8 - _FOOTER_SIZE
    opcode, length = _RECORD_HEADER.unpack_from(buf, footer_at)
    if opcode != 0x02 or length != _FOOTER_SIZE - 9:
        return None
    summary_start, _offsets, crc = struct.unpack_from('<QQI', buf, footer_at + 9)
    if not summary_start or summary_start > footer_at:
        return None
    if crc and zlib.crc32(buf[summary_start:footer_at + 9 + 16]) != crc:
        return None
    f.seek(0)
    try:
        return make_reader(f).get_summary()
    except CORRUPT_RECORD_ERRORS:
        return None


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
    with _mapped(path) as (f, buf, size):
        summary = _summary(path, f, buf, size) if _is_finished(f, size) else None
        if summary is not None and summary.chunk_indexes:
            contents.chunk_indexes = sorted(
                summary.chunk_indexes,
                key=lambda c: (c.message_start_time, c.chunk_start_offset))
            contents.indexed = True
        if not scan and summary is not None and summary.statistics is not None:
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
        _scan_contents(path, buf, size, contents)
    return contents


def _scan_contents(path: Path, buf: bytes | mmap.mmap, size: int,
                   contents: McapContents) -> None:
    contents.complete = False
    schemas: dict[int, Schema] = {}
    counts: dict[int, int] = defaultdict(int)
    start, end = 2**63 - 1, 0
    open_gaps = 0
    for record in _records(path, buf, size, contents):
        for _ in range(len(contents.damaged) - len(contents.gaps)):
            contents.gaps.append((contents.last_ns, None))   # closed by the next message
            open_gaps += 1
        if isinstance(record, Message):
            counts[record.channel_id] += 1
            start = min(start, record.log_time)
            end = max(end, record.log_time)
            contents.last_ns = record.log_time
            while open_gaps:
                k = len(contents.gaps) - open_gaps
                contents.gaps[k] = (contents.gaps[k][0], record.log_time)
                open_gaps -= 1
        elif isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            contents.channels[record.id] = _channel_info(record, schemas)
        elif isinstance(record, Footer):
            contents.complete = contents.footer = True
    for _ in range(len(contents.damaged) - len(contents.gaps)):
        contents.gaps.append((contents.last_ns, None))
    contents.channel_counts = dict(counts)
    contents.message_count = sum(counts.values())
    if contents.message_count:
        contents.start_ns, contents.end_ns = start, end


def iter_scanned_messages(path: Path, contents: McapContents | None = None,
                          channel_ids: set[int] | None = None) -> Iterator[McapMessage]:
    """Every readable message of a file in file order, by a scan (damage skipped, described in
    ``contents`` when given); works on unfinished files.

    Args:
        path: The .mcap file.
        contents: Receives what the scan skipped (``damaged``, ``skipped_chunks``, ...).
        channel_ids: Only messages of these channels (default: all).
    """
    path = Path(path)
    contents = contents if contents is not None else McapContents(path)
    with _mapped(path) as (_f, buf, size):
        schemas: dict[int, Schema] = {}
        channels: dict[int, ChannelInfo] = {}
        for record in _records(path, buf, size, contents):
            if isinstance(record, Message):
                if channel_ids is not None and record.channel_id not in channel_ids:
                    continue
                channel = channels.get(record.channel_id)
                if channel is not None:
                    yield McapMessage(channel, record.log_time, record.publish_time,
                                      record.data)
            elif isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = _channel_info(record, schemas)


def iter_mcap_messages(path: Path) -> Iterator[tuple[ChannelInfo, int, bytes]]:
    """``(channel, log_time_ns, data)`` for every readable message, in file order (a scan:
    damaged chunks are skipped; an unfinished file is read to its last complete record)."""
    for m in iter_scanned_messages(path):
        yield m.channel, m.log_time, m.data


def iter_indexed_messages(contents: McapContents, *, channel_ids: set[int] | None = None,
                          start_ns: int | None = None,
                          on_skip: Callable[[str], None] | None = None,
                          ) -> Iterator[McapMessage]:
    """Messages of a file with an intact summary, in log time order, through its chunk index.

    Each chunk is read at its offset and checked (framing, CRC, decompression); one that fails
    is skipped, and ``on_skip`` gets a sentence with its byte offset and the number of messages
    its message index records give. Ties in log time keep file order.

    Args:
        contents: :func:`read_mcap_contents` of the file (``indexed`` must be True).
        channel_ids: Only messages of these channels (default: all).
        start_ns: Only messages at or after this log time (ns).
        on_skip: Called once per skipped chunk.
    """
    if not contents.indexed or contents.chunk_indexes is None:
        msg = f'{contents.path} has no intact summary to read it by its index; scan it instead.'
        raise BagError(msg)
    chunks = [c for c in contents.chunk_indexes
              if (start_ns is None or c.message_end_time >= start_ns)
              and (channel_ids is None or not c.message_index_offsets
                   or not channel_ids.isdisjoint(c.message_index_offsets))]
    channels = contents.channels
    name = contents.path.name
    with _mapped(contents.path) as (_f, buf, size):

        def load(index: ChunkIndex) -> list[tuple[int, int, int, Message]]:
            offset = index.chunk_start_offset
            chunk = _chunk_at(buf, offset, size, strict=False)
            try:
                if chunk is None or index.chunk_length != _RECORD_HEADER.unpack_from(
                        buf, offset)[1] + 9:
                    msg = 'the bytes at its offset do not frame a chunk'
                    raise McapError(msg)
                records = _chunk_records(chunk)
            except CORRUPT_RECORD_ERRORS as exc:
                if on_skip is not None:
                    count = _chunk_index_count(buf, index, size)
                    on_skip(f'{name}: chunk at byte {offset} ({index.chunk_length} bytes) is '
                            f'corrupt ({exc}; {_lost(count)}); it was skipped.')
                return []
            out = []
            for k, r in enumerate(records):
                if not isinstance(r, Message):
                    continue
                if channel_ids is not None and r.channel_id not in channel_ids:
                    continue
                if start_ns is not None and r.log_time < start_ns:
                    continue
                out.append((r.log_time, offset, k, r))
            out.sort(key=lambda e: (e[0], e[2]))
            return out

        heap: list[tuple[int, int, int, Message]] = []
        i, n = 0, len(chunks)
        while i < n or heap:
            if i < n and (not heap or chunks[i].message_start_time <= heap[0][0]):
                entries = load(chunks[i])
                i += 1
                if not heap and (i >= n or not entries
                                 or entries[-1][0] <= chunks[i].message_start_time):
                    # the common case: chunks in time order that do not overlap
                    for _, _, _, r in entries:
                        channel = channels.get(r.channel_id)
                        if channel is not None:
                            yield McapMessage(channel, r.log_time, r.publish_time, r.data)
                    continue
                for entry in entries:
                    heapq.heappush(heap, entry)
                continue
            r = heapq.heappop(heap)[3]
            channel = channels.get(r.channel_id)
            if channel is not None:
                yield McapMessage(channel, r.log_time, r.publish_time, r.data)


def is_finished(path: Path) -> bool:
    """True when an MCAP file ends with its closing magic (its writer finished it)."""
    try:
        size = Path(path).stat().st_size
        with Path(path).open('rb') as f:
            return _is_finished(f, size)
    except OSError:
        return False


def recover_mcap(path: Path, out: Path | None = None) -> tuple[int, McapContents]:
    """Write every readable record of an MCAP file into a finished file (summary, footer).

    Every readable record is copied (schemas, channels, messages with both times), damaged
    chunks and a cut-off tail, which no reader can use, are left out; the chunks keep the
    original's compression. Written atomically: a full disk leaves no partial copy.

    Args:
        path: The damaged or unfinished file (never changed).
        out: Where to write the repaired file (default: replace ``path``).

    Returns:
        The number of messages written, and what the scan skipped (``damaged``,
        ``skipped_chunks``, ``lost_known``, ``stopped_at``).
    """
    from mcap.writer import CompressionType
    from mcap.writer import Writer as McapWriter

    path = Path(path)
    contents = McapContents(path)
    counted = [0]

    def rewrite(tmp: Path) -> None:
        with _mapped(path) as (_f, buf, size), tmp.open('wb') as dest:
            compression = _first_compression(buf, size)
            writer = McapWriter(dest, compression={'zstd': CompressionType.ZSTD,
                                                   'lz4': CompressionType.LZ4}.get(
                                                       compression, CompressionType.NONE))
            writer.start(profile='ros2', library='mindgrasp-ros bag recovery (mcap python)')
            schema_ids: dict[int, int] = {}
            channel_ids: dict[int, int] = {}
            for record in _records(path, buf, size, contents):
                if isinstance(record, Message):
                    if record.channel_id in channel_ids:
                        writer.add_message(channel_ids[record.channel_id], record.log_time,
                                           record.data, record.publish_time, record.sequence)
                        counted[0] += 1
                elif isinstance(record, Schema) and record.id not in schema_ids:
                    schema_ids[record.id] = writer.register_schema(record.name, record.encoding,
                                                                   record.data)
                elif isinstance(record, Channel) and record.id not in channel_ids:
                    channel_ids[record.id] = writer.register_channel(
                        record.topic, record.message_encoding,
                        schema_ids.get(record.schema_id, 0), dict(record.metadata))
            writer.finish()

    write_atomic(path if out is None else Path(out), rewrite)
    return counted[0], contents


def _first_compression(buf: bytes | mmap.mmap, size: int) -> str:
    """The compression of the file's first intact chunk ('' when none)."""
    start = _resync(buf, 8, size)
    chunk = None if start is None else _chunk_at(buf, start, size, strict=False)
    return chunk.compression if chunk is not None else ''


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

