"""Bag integrity: verify every MCAP file of a bag, and reindex (repair) a crashed recording.

``reindex`` is what ``ros2 bag reindex`` does for MCAP bags, plus finishing the files: each
unfinished or damaged .mcap file is copied with every readable record (a damaged chunk costs only
its own messages) into a finished file with a summary, so the plain ``mcap`` reader
(``make_reader(f).iter_messages()``, which needs the summary) and every rosbag2 tool open it; the
original is kept beside it as ``<name>.damaged`` (as ``mcap recover`` writes to a new file); then
metadata.yaml is rebuilt from the files.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path
from typing import Any

from .errors import BagError
from .mcap_scan import is_finished, read_mcap_contents, recover_mcap, verify_mcap
from .metadata import DAMAGED_SUFFIX, METADATA_FILE, load_metadata, mcap_files, rebuild_metadata

__all__ = ['reindex', 'verify_bag']


def verify_bag(bag: Path) -> list[str]:
    """Damage in the bag's MCAP files (sentences naming the file and the byte offset)."""
    bag = Path(bag)
    files = mcap_files(bag) if bag.is_dir() else ([bag] if bag.suffix == '.mcap' else [])
    problems: list[str] = []
    for path in files:
        problems += verify_mcap(path)
    return problems


def _backup_name(path: Path) -> Path:
    """``<name>.damaged`` beside ``path`` (``.damaged-1``, ... when taken)."""
    backup = path.with_name(path.name + DAMAGED_SUFFIX)
    k = 0
    while backup.exists():
        k += 1
        backup = path.with_name(f'{path.name}{DAMAGED_SUFFIX}-{k}')
    return backup


def _recorded(path: Path, metadata: dict[str, Any] | None) -> int | None:
    """Messages the file held when it was written: its summary, else metadata.yaml's entry."""
    with contextlib.suppress(BagError):
        contents = read_mcap_contents(path)
        if contents.footer:
            return contents.message_count
    for entry in (metadata or {}).get('files') or []:
        if isinstance(entry, dict) and entry.get('path') == path.name:
            with contextlib.suppress(TypeError, ValueError):
                return int(entry.get('message_count'))
    return None


def reindex(bag: Path) -> list[str]:
    """Repair unfinished or damaged .mcap files and rebuild metadata.yaml; never write over the
    only copy.

    Each file to repair is copied with every readable record (damaged chunks and a cut-off tail
    left out) into a finished file with a summary; then the original is renamed
    ``<name>.damaged`` and the repaired copy takes its name, so readers of the bag see the repaired
    file and nothing recorded is deleted. A corrupt metadata.yaml is kept the same way.

    Returns what was done, as sentences: per repaired file the messages kept, how many were lost
    and why (each damage with its byte offset), and where the original is.

    Raises:
        BagError: ``bag`` is not a bag directory with .mcap files.
        OSError: a write failed (a full disk): the bag is as it was.
    """
    bag = Path(bag)
    if not bag.is_dir() or not mcap_files(bag):
        msg = (f'{bag} is not an MCAP bag directory (no .mcap file); pass a run directory or '
               'its bag folder.')
        raise BagError(msg)
    metadata = None
    if (bag / METADATA_FILE).exists():
        try:
            metadata = load_metadata(bag)
        except BagError:
            metadata = None
    done = []
    for path in mcap_files(bag):
        problems = verify_mcap(path)
        if is_finished(path) and not problems:
            continue
        recorded = _recorded(path, metadata)
        tmp = path.with_name(f'.{path.name}.repaired')
        kept, contents = recover_mcap(path, tmp)
        backup = _backup_name(path)
        os.replace(path, backup)
        os.replace(tmp, path)
        if recorded is not None:
            lost = f'{max(0, recorded - kept)} of {recorded} recorded lost'
        elif contents.lost_known:
            lost = f'at least {contents.lost_known} lost (the file had no summary to say more)'
        else:
            lost = 'the number lost is unknown (the file had no summary or metadata entry)'
        done.append(f'{path.name} has been rewritten with its summary: {kept} message(s) kept, '
                    f'{lost}; the original is kept as {backup.name}.')
        done += [f'  lost: {p}' for p in problems]
    metadata_file = bag / METADATA_FILE
    if metadata_file.exists() and metadata is None:
        backup = _backup_name(metadata_file)
        os.replace(metadata_file, backup)
        done.append(f'{METADATA_FILE} was corrupt; it is kept as {backup.name}.')
    rebuild_metadata(bag)
    done.append(f'metadata.yaml has been rebuilt from the .mcap files: {metadata_file}.')
    return done
