"""A run directory or a bag: the commands take either (``runs/<run>`` or ``runs/<run>/bag``)."""

from __future__ import annotations

from pathlib import Path

from .errors import BagError
from .metadata import METADATA_FILE

__all__ = ['resolve_bag', 'run_dir_of']


def resolve_bag(path: str | Path) -> Path:
    """The bag of ``path``: ``path/bag`` for a run directory, else ``path`` itself.

    A bag is a directory with metadata.yaml or .mcap/.db3 files, or one such file.

    Raises
    ------
    BagError
        ``path`` does not exist.
    """
    p = Path(path).expanduser()
    if not p.exists():
        msg = (f'{p} does not exist; pass a run directory (runs/<run>) or its bag folder '
               '(runs/<run>/bag).')
        raise BagError(msg)
    if p.is_dir() and not (p / METADATA_FILE).exists() and (p / 'bag').is_dir():
        return p / 'bag'
    return p


def run_dir_of(bag: Path) -> Path | None:
    """The run directory holding ``bag`` (it has params.yaml), or None for a bare bag."""
    parent = Path(bag).resolve().parent
    return parent if (parent / 'params.yaml').exists() else None
