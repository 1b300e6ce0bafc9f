"""``bag info`` text: files, size, duration, time range, and per topic type, count and rate."""

from __future__ import annotations

import datetime as dt
from pathlib import Path
from typing import Any

from .reader import BagReader

__all__ = ['format_info', 'summarize']


def summarize(reader: BagReader) -> dict[str, Any]:
    """Machine-readable summary of an opened bag (times in ns, sizes in bytes, rates in Hz)."""
    duration_s = reader.duration_ns / 1e9
    topics = []
    for info in sorted(reader.topics.values(), key=lambda t: t.name):
        rate = (info.message_count - 1) / duration_s if duration_s > 0 and info.message_count > 1 \
            else 0.0
        topics.append({'name': info.name, 'type': info.type, 'count': info.message_count,
                       'rate_hz': rate, 'serialization_format': info.serialization_format})
    return {
        'path': str(reader.path),
        'files': [str(Path(f).name) for f in reader.files],
        'size_bytes': sum(Path(f).stat().st_size for f in reader.files if Path(f).exists()),
        'storage': reader.storage,
        'start_ns': reader.start_ns,
        'end_ns': reader.end_ns,
        'duration_ns': reader.duration_ns,
        'message_count': reader.message_count,
        'complete': reader.complete,
        'topics': topics,
        'notes': list(reader.notes),
    }


def _size(n: float) -> str:
    for unit in ('B', 'KiB', 'MiB', 'GiB'):
        if n < 1024 or unit == 'GiB':
            return f'{n:.1f} {unit}' if unit != 'B' else f'{int(n)} B'
        n /= 1024
    return f'{n:.1f} GiB'


def _stamp(ns: int) -> str:
    when = dt.datetime.fromtimestamp(ns / 1e9, tz=dt.timezone.utc)
    return f'{when:%b %d %Y %H:%M:%S}.{ns % 1_000_000_000:09d} UTC ({ns / 1e9:.9f})'


def format_info(summary: dict[str, Any]) -> str:
    """The summary as text in the layout of ``ros2 bag info``."""
    lines = [
        f'Files:             {", ".join(summary["files"])}',
        f'Bag size:          {_size(summary["size_bytes"])}',
        f'Storage id:        {summary["storage"]}',
        f'Duration:          {summary["duration_ns"] / 1e9:.9f} s',
    ]
    if summary['message_count']:
        lines += [f'Start:             {_stamp(summary["start_ns"])}',
                  f'End:               {_stamp(summary["end_ns"])}']
    lines.append(f'Messages:          {summary["message_count"]}')
    width = max((len(t['name']) for t in summary['topics']), default=0)
    twidth = max((len(t['type']) for t in summary['topics']), default=0)
    for i, t in enumerate(summary['topics']):
        head = 'Topic information: ' if i == 0 else ' ' * 19
        lines.append(f'{head}Topic: {t["name"]:<{width}} | Type: {t["type"]:<{twidth}} | '
                     f'Count: {t["count"]:>7} | Rate: {t["rate_hz"]:8.2f} Hz | '
                     f'Serialization Format: {t["serialization_format"]}')
    if not summary['topics']:
        lines.append('Topic information: (no topics)')
    lines += [f'Note: {note}' for note in summary['notes']]
    damage = summary.get('damage') or {}
    lines += [f'Damage: {problem}' for problem in damage.get('problems', [])]
    if damage.get('damaged'):
        lines.append(f'Readable:          {damage["summary"]}')
    return '\n'.join(lines)
