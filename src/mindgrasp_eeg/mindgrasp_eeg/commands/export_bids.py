"""Export recorded runs (or every phase of a calibration session) as an EEG-BIDS dataset.

Examples::

    mindgrasp export bids subjects/B01/<session> --root bids --subject B01 --session 1
    mindgrasp export bids runs/<time>_demo --root bids --subject B01 --line-freq 60

Writes EDF with channels.tsv, eeg.json, events.tsv (prompts, targets, grasp results, controller
states) and the 10-20 electrodes through mne-bids; the bags go to ``sourcedata/``. Check the result
with ``bids-validator-deno ROOT -r`` (-r: the robot motion's derivatives dataset too).
"""

from __future__ import annotations

import argparse
import sys

from mindgrasp_common.cli_checks import positive_float
from mindgrasp_eeg import EEGError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp export bids``."""
    parser.add_argument('paths', nargs='+', metavar='RUN_DIR',
                        help='run directories, bags or calibration session folders')
    parser.add_argument('--root', required=True, help='root folder of the BIDS dataset')
    parser.add_argument('--subject', required=True, help='participant label (letters, digits)')
    parser.add_argument('--session', default=None, help='session label (letters, digits)')
    parser.add_argument('--line-freq', type=positive_float, default=50.0,
                        help='power line frequency for eeg.json (Hz; default 50)')
    parser.add_argument('--reference', default=None,
                        help="the amplifier's EEG reference for eeg.json (e.g. Cz; default: "
                             "the stream's metadata, else n/a)")
    parser.add_argument('--manufacturer', default=None,
                        help="the amplifier's manufacturer for eeg.json (default: the stream's "
                             'metadata, else n/a)')
    parser.add_argument('--model', default=None,
                        help="the amplifier's model for eeg.json (default: the stream's "
                             'metadata, else none)')
    parser.add_argument('--overwrite', action='store_true', help='replace runs that exist')


def main(args: argparse.Namespace) -> int:
    """Export; 0 on success, 1 with one line on bad input."""
    from mindgrasp_eeg.bids import export_bids

    try:
        files = export_bids(args.paths, args.root, args.subject, args.session,
                            line_freq=args.line_freq, reference=args.reference,
                            manufacturer=args.manufacturer, model=args.model,
                            overwrite=args.overwrite)
    except EEGError as exc:
        print(f'mindgrasp export bids: {exc}', file=sys.stderr)
        return 1
    for f in files:
        print(f'Wrote {f}')
    print(f'BIDS dataset {args.root}: {len(files)} run(s) of sub-{args.subject}; check it with '
          f'`bids-validator-deno {args.root} -r` (-r: its derivatives too).')
    return 0
