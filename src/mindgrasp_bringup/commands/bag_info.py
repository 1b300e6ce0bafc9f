"""Print a bag's duration, size, and per topic message type, count and rate."""

from __future__ import annotations

import argparse
import sys

import yaml

from mindgrasp_bringup.bag import BagError, BagReader
from mindgrasp_bringup.bag.info import format_info, summarize
from mindgrasp_bringup.bag.metadata import METADATA_FILE


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag info <bag> [--yaml] [--no-rebuild]``."""
    parser.add_argument('bag', help='bag directory (holding metadata.yaml), or an .mcap/.db3 file')
    parser.add_argument('--yaml', action='store_true', help='print the summary as YAML')
    parser.add_argument('--no-rebuild', action='store_true',
                        help='do not write a missing metadata.yaml (rebuilt from the .mcap files '
                             'by default)')


def main(args: argparse.Namespace) -> int:
    """Print the summary; rebuild a missing metadata.yaml. 1 when the bag cannot be read."""
    try:
        reader = BagReader(args.bag).open()
    except BagError as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    try:
        if reader.path.is_dir() and not (reader.path / METADATA_FILE).exists() \
                and not args.no_rebuild:
            path = reader.rebuild_metadata()
            reader.notes = [n for n in reader.notes if 'metadata.yaml was missing' not in n]
            reader.notes.append(f'metadata.yaml was missing and has been rebuilt: {path}.')
        summary = summarize(reader)
    except (BagError, OSError) as exc:
        print(f'mindgrasp bag info: {exc}', file=sys.stderr)
        return 1
    finally:
        reader.close()
    if args.yaml:
        print(yaml.safe_dump(summary, sort_keys=False), end='')
    else:
        print(format_info(summary))
    return 0
