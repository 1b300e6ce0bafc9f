"""Print a bag's duration, size, and per topic message type, count and rate; check its files."""

from __future__ import annotations

import argparse
import sys

import yaml

from mindgrasp_bringup.bag import BagError, BagReader
from mindgrasp_bringup.bag.info import format_info, summarize
from mindgrasp_bringup.bag.integrity import reindex, verify_bag
from mindgrasp_bringup.bag.metadata import METADATA_FILE
from mindgrasp_bringup.bag.paths import resolve_bag


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag info <bag> [--yaml] [--no-rebuild] [--no-verify]``."""
    parser.add_argument('bag', help='run directory (runs/<run>), bag directory (holding '
                                    'metadata.yaml), or an .mcap/.db3 file')
    parser.add_argument('--yaml', action='store_true', help='print the summary as YAML')
    parser.add_argument('--fix', action='store_true',
                        help='repair a bag whose recorder was killed (same as `mindgrasp bag '
                             'reindex`)')
    parser.add_argument('--no-rebuild', action='store_true',
                        help='do not write a missing metadata.yaml (rebuilt from the .mcap files '
                             'by default)')
    parser.add_argument('--no-verify', action='store_true',
                        help='do not read every record to check chunk CRCs (faster on big bags)')


def main(args: argparse.Namespace) -> int:
    """Print the summary; rebuild a missing metadata.yaml. 1 when the bag cannot be read or is
    damaged (each damage is printed with its file and byte offset)."""
    try:
        bag = resolve_bag(args.bag)
        fixed = reindex(bag) if args.fix else []
        reader = BagReader(bag).open()
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    try:
        if reader.path.is_dir() and not (reader.path / METADATA_FILE).exists() \
                and not args.no_rebuild:
            path = reader.rebuild_metadata()
            reader.notes = [n for n in reader.notes if 'metadata.yaml was missing' not in n]
            reader.notes.append(f'metadata.yaml was missing and has been rebuilt: {path}.')
        reader.notes.extend(fixed)
        summary = summarize(reader)
        summary['damage'] = [] if args.no_verify or reader.storage != 'mcap' \
            else verify_bag(bag)
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    finally:
        reader.close()
    if args.yaml:
        print(yaml.safe_dump(summary, sort_keys=False), end='')
    else:
        print(format_info(summary))
    return 1 if summary['damage'] else 0
