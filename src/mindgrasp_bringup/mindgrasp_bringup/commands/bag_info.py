"""Print a bag's duration, size, and per topic message type, count and rate."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import yaml

from mindgrasp_bringup.bag import BagError, BagReader
from mindgrasp_bringup.bag.info import format_info, summarize
from mindgrasp_bringup.bag.mcap_scan import is_finished, recover_mcap
from mindgrasp_bringup.bag.metadata import METADATA_FILE, mcap_files, rebuild_metadata


def repair(bag: Path) -> list[str]:
    """Finish unfinished .mcap files and rebuild metadata.yaml; what was done, as sentences."""
    if not bag.is_dir():
        msg = f'--fix needs a bag directory; {bag} is not one.'
        raise BagError(msg)
    done = []
    for path in mcap_files(bag):
        if not is_finished(path):
            kept = recover_mcap(path)
            done.append(f'{path.name} was unfinished and has been rewritten with its summary '
                        f'({kept} message(s) kept).')
    if mcap_files(bag):
        rebuild_metadata(bag)
        done.append(f'metadata.yaml has been rebuilt from the .mcap files: {bag / METADATA_FILE}.')
    return done


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """``mindgrasp bag info <bag> [--yaml] [--no-rebuild]``."""
    parser.add_argument('bag', help='bag directory (holding metadata.yaml), or an .mcap/.db3 file')
    parser.add_argument('--yaml', action='store_true', help='print the summary as YAML')
    parser.add_argument('--fix', action='store_true',
                        help='repair a bag whose recorder was killed: rewrite unfinished .mcap '
                             'files with their summary and rebuild metadata.yaml, so every '
                             'rosbag2 tool can open it')
    parser.add_argument('--no-rebuild', action='store_true',
                        help='do not write a missing metadata.yaml (rebuilt from the .mcap files '
                             'by default)')


def main(args: argparse.Namespace) -> int:
    """Print the summary; rebuild a missing metadata.yaml. 1 when the bag cannot be read."""
    fixed: list[str] = []
    if args.fix:
        try:
            fixed = repair(Path(args.bag))
        except (BagError, OSError) as exc:
            print(f'mindgrasp bag info: {exc}', file=sys.stderr)
            return 1
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
        reader.notes.extend(fixed)
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
