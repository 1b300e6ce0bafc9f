"""Print a bag's duration, size, and per topic message type, count and rate; check its files.

Read-only: it never writes into the bag or the run directory (a full disk, a read-only copy);
`mindgrasp bag reindex` (or `--fix`) repairs a bag and writes a missing metadata.yaml.
"""

from __future__ import annotations

import argparse
import sys

import yaml

from mindgrasp_bag import BagError, BagReader
from mindgrasp_bag.damage import ALLOW_DAMAGED_HELP, assess_bag
from mindgrasp_bag.info import format_info, summarize
from mindgrasp_bag.integrity import reindex
from mindgrasp_bag.paths import resolve_bag


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag info <bag> [--yaml] [--fix] [--no-verify] [--allow-damaged]``."""
    parser.add_argument('bag', help='run directory (runs/<run>), bag directory (holding '
                                    'metadata.yaml), or an .mcap/.db3 file')
    parser.add_argument('--yaml', action='store_true', help='print the summary as YAML')
    parser.add_argument('--fix', action='store_true',
                        help='repair a bag whose recorder was killed and write a missing '
                             'metadata.yaml (same as `mindgrasp bag reindex`; the only option '
                             'that writes)')
    # never rebuilding is the default now; kept so that older scripts still run
    parser.add_argument('--no-rebuild', action='store_true', help=argparse.SUPPRESS)
    parser.add_argument('--no-verify', action='store_true',
                        help='do not read every record to check chunk CRCs (faster on big bags)')
    parser.add_argument('--allow-damaged', action='store_true', help=ALLOW_DAMAGED_HELP)


def main(args: argparse.Namespace) -> int:
    """Print the summary. 2 when the path does not exist (as ``ros2 bag info``); 1 when the bag
    cannot be read, or is damaged without ``--allow-damaged`` (each damage is printed with its
    file and byte offset, and the readable vs recorded message counts)."""
    try:
        bag = resolve_bag(args.bag)
    except BagError as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 2
    try:
        fixed = reindex(bag) if args.fix else []
        reader = BagReader(bag).open()
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    try:
        reader.notes.extend(fixed)
        summary = summarize(reader)
        damage = None if args.no_verify or reader.storage != 'mcap' else assess_bag(bag)
        summary['damage'] = damage.as_dict() if damage is not None else None
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    finally:
        reader.close()
    if args.yaml:
        print(yaml.safe_dump(summary, sort_keys=False), end='')
    else:
        print(format_info(summary))
    return 1 if damage is not None and damage.damaged and not args.allow_damaged else 0
