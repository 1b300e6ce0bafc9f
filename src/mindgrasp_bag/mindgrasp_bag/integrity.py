"""Bag integrity: verify every MCAP file of a bag, and reindex (repair) a crashed recording.

``reindex`` is what ``ros2 bag reindex`` does for MCAP bags, plus finishing the files: each
unfinished or damaged .mcap file is rewritten with every readable record and a summary, so the
plain ``mcap`` reader (``make_reader(f).iter_messages()``, which needs the summary) and every
rosbag2 tool open it; then metadata.yaml is rebuilt from the files.
"""

from __future__ import annotations

from pathlib import Path

from .errors import BagError
from .mcap_scan import is_finished, recover_mcap, verify_mcap
from .metadata import METADATA_FILE, mcap_files, rebuild_metadata

__all__ = ['reindex', 'verify_bag']


def verify_bag(bag: Path) -> list[str]:
    """Damage in the bag's MCAP files (sentences naming the file and the byte offset)."""
    bag = Path(bag)
    files = mcap_files(bag) if bag.is_dir() else ([bag] if bag.suffix == '.mcap' else [])
    problems: list[str] = []
    for path in files:
        problems += verify_mcap(path)
    return problems


def reindex(bag: Path) -> list[str]:
    """Rewrite unfinished or damaged .mcap files with a summary and rebuild metadata.yaml.

    Returns what was done, as sentences.

    Raises:
        BagError: ``bag`` is not a bag directory with .mcap files.
    """
    bag = Path(bag)
    if not bag.is_dir() or not mcap_files(bag):
        msg = (f'{bag} is not an MCAP bag directory (no .mcap file); pass a run directory or '
               'its bag folder.')
        raise BagError(msg)
    done = []
    for path in mcap_files(bag):
        if not is_finished(path) or verify_mcap(path):
            kept = recover_mcap(path)
            done.append(f'{path.name} has been rewritten with its summary ({kept} message(s) '
                        'kept).')
    rebuild_metadata(bag)
    done.append(f'metadata.yaml has been rebuilt from the .mcap files: {bag / METADATA_FILE}.')
    return done
