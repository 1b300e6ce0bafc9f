"""One damage policy for every bag tool: read what can be read, say and count what was skipped.

    damage = assess_bag(Path('runs/<run>/bag'))
    damage.damaged            # True: a record skipped, a file cut off, or messages missing
    damage.lines()            # one sentence per problem, then the count (for stderr / info)
    damage.as_dict()          # the counts for --json / --yaml output

A bag is damaged when a scan of every record of its MCAP files skips a corrupt record (a chunk
whose CRC fails), stops at a record cut off or garbage, finds a file without its footer (the
recorder was killed), or reads fewer messages than metadata.yaml (or the files' summaries) says
the bag holds. ``bag info``, ``bag play`` and ``replay`` all call :func:`assess_bag`, use every
readable message, print what was lost, put the counts in their machine-readable output, and exit
1 on a damaged bag unless given ``--allow-damaged`` (as ``mcap doctor`` fails on a damaged file
while ``mcap recover`` / ``mindgrasp bag reindex`` keep what is readable).

sqlite3 bags are not scanned (SQLite has its own integrity checks); they report no damage.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import BagError
from .mcap_scan import damage_sentences, read_mcap_contents
from .metadata import METADATA_FILE, load_metadata, mcap_files

__all__ = ['ALLOW_DAMAGED_HELP', 'BagDamage', 'assess_bag']

#: help of every tool's ``--allow-damaged`` option
ALLOW_DAMAGED_HELP = ('use the readable part of a damaged bag and exit 0 (without it, damage '
                      'is reported and the exit code is 1); `mindgrasp bag reindex` repairs '
                      'what can be repaired')


@dataclass
class BagDamage:
    """What a bag lost (times in ns).

    Attributes:
        expected_messages: What metadata.yaml (else the files' summaries) says the bag holds;
            None when neither exists (a killed recorder's bag).
        readable_messages: Messages a scan of every record can read.
        skipped_records: Damaged stretches skipped (a chunk whose CRC fails or no longer
            decompresses, bytes that do not frame a record up to the next intact chunk).
        skipped_bytes: Bytes those stretches span.
        cut_files: Files whose scan stopped early (cut off, garbage) or that have no footer.
        lost_spans: Bag time ranges ``(start, end)`` where messages are missing: between the
            last message before a skipped record and the first after it, and from the last
            readable message to the end the metadata gives for a cut file.
        problems: One sentence per problem, naming the file and the byte offset.
        end_ns: The bag's end as its metadata gives it (0 when unknown).
    """

    expected_messages: int | None
    readable_messages: int
    skipped_records: int = 0
    skipped_bytes: int = 0
    cut_files: int = 0
    lost_spans: list[tuple[int, int]] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    end_ns: int = 0

    @property
    def lost_messages(self) -> int | None:
        """Messages the metadata declares but no reader can read (None: nothing declared)."""
        if self.expected_messages is None:
            return None
        return max(0, self.expected_messages - self.readable_messages)

    @property
    def lost_span_ns(self) -> int:
        """Total bag time with missing messages (ns)."""
        return sum(end - start for start, end in self.lost_spans)

    @property
    def damaged(self) -> bool:
        """True when anything recorded cannot be read."""
        return bool(self.problems) or bool(self.lost_messages)

    def as_dict(self) -> dict[str, Any]:
        """The counts, for --json / --yaml output (times in s)."""
        return {'damaged': self.damaged, 'expected_messages': self.expected_messages,
                'readable_messages': self.readable_messages,
                'lost_messages': self.lost_messages, 'skipped_records': self.skipped_records,
                'skipped_bytes': self.skipped_bytes,
                'cut_files': self.cut_files, 'lost_span_s': round(self.lost_span_ns / 1e9, 6),
                'problems': list(self.problems), 'summary': self.count_line()}

    def count_line(self) -> str:
        """One sentence with the counts."""
        expected = ('(no metadata.yaml or summary says how many were recorded)'
                    if self.expected_messages is None else
                    f'of {self.expected_messages} recorded ({self.lost_messages} lost)')
        return (f'{self.readable_messages} message(s) readable {expected}; '
                f'{self.skipped_records} damaged record(s) skipped ({self.skipped_bytes} bytes), '
                f'{self.cut_files} file(s) cut off; {self.lost_span_ns / 1e9:.3f} s of bag time '
                'has missing messages.')

    def lines(self) -> list[str]:
        """Each problem, then the counts (empty for a sound bag)."""
        if not self.damaged:
            return []
        return [*self.problems, self.count_line()]


def _declared(bag: Path, files: list[Path]) -> tuple[int | None, int, int]:
    """Message count, start and end (ns) that the metadata (else the summaries) declare."""
    if bag.is_dir() and (bag / METADATA_FILE).exists():
        try:
            info = load_metadata(bag)
        except BagError:
            info = None
        if info is not None:
            start = int((info.get('starting_time') or {}).get('nanoseconds_since_epoch', 0))
            duration = int((info.get('duration') or {}).get('nanoseconds', 0))
            return int(info.get('message_count', 0)), start, start + duration
    summaries = [read_mcap_contents(f) for f in files]
    if summaries and all(s.footer for s in summaries):
        counted = [s for s in summaries if s.message_count]
        return (sum(s.message_count for s in summaries),
                min((s.start_ns for s in counted), default=0),
                max((s.end_ns for s in counted), default=0))
    return None, 0, 0


def assess_bag(bag: Path) -> BagDamage:
    """Read every record of the bag's MCAP files and compare with what the bag declares.

    Args:
        bag: A bag directory or one .mcap/.db3 file.

    Raises:
        BagError: a file cannot be opened or is not MCAP.
    """
    bag = Path(bag)
    files = mcap_files(bag) if bag.is_dir() else ([bag] if bag.suffix == '.mcap' else [])
    if not files:
        return BagDamage(None, 0)
    expected, _start, end = _declared(bag, files)
    damage = BagDamage(expected, 0, end_ns=end)
    for path in files:
        contents = read_mcap_contents(path, scan=True)
        damage.readable_messages += contents.message_count
        damage.skipped_records += len(contents.damaged)
        damage.skipped_bytes += contents.skipped_bytes
        damage.problems += damage_sentences(contents)
        cut = bool(contents.stopped_at) or not contents.footer
        damage.cut_files += cut
        for before, after in contents.gaps:
            if before is not None and after is not None:
                damage.lost_spans.append((before, after))
            elif before is not None and end > before:
                damage.lost_spans.append((before, end))
        if cut and contents.last_ns is not None and end > contents.last_ns:
            damage.lost_spans.append((contents.last_ns, end))
    damage.lost_spans = _merged(damage.lost_spans)
    return damage


def _merged(spans: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Overlapping time ranges joined (a gap at a file's end is also its cut)."""
    out: list[tuple[int, int]] = []
    for start, end in sorted(spans):
        if out and start <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], end))
        else:
            out.append((start, end))
    return out
