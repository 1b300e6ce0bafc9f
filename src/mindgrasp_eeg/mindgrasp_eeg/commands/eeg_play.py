"""Stream EEG files (EDF/BDF/GDF/FIF/XDF, or eegbci:<subject>:<runs>) over LSL with markers.

Examples::

    mindgrasp eeg play ../shared/data/MNE-eegbci-data/files/eegmmidb/1.0.0/S001/S001R04.edf
    mindgrasp eeg play eegbci:1:4,8 --name eegmmidb --rate 2 --loop
    mindgrasp eeg play eegbci:1:4 --manufacturer BCI2000 --model 'BCI2000 64 ch' --reference n/a
"""

from __future__ import annotations

import argparse
import sys

from mindgrasp_common.cli_checks import non_negative_float, positive_float
from mindgrasp_eeg import EEGError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp eeg play``."""
    parser.add_argument('files', nargs='+', metavar='FILE',
                        help='EEG files, played back to back; eegbci:<subject>:<run>[,<run>] '
                             'names EEGMMIDB runs (MNE loader, $MNE_DATASETS_EEGBCI_PATH)')
    parser.add_argument('--name', default='mindgrasp_player',
                        help='LSL stream name (markers: <name>-markers)')
    parser.add_argument('--source-id', default='', help='LSL source_id (default: the name)')
    parser.add_argument('--type', default='EEG', help='LSL stream type')
    parser.add_argument('--rate', type=positive_float, default=1.0,
                        help='playback speed, 1 = real time, 2 = twice as fast')
    parser.add_argument('--loop', action='store_true', help='start again at the end')
    parser.add_argument('--duration', type=non_negative_float, default=0.0,
                        help='stop after this many seconds of wall time (0: at the end)')
    amplifier = parser.add_argument_group(
        'amplifier', "the amplifier that recorded the files, declared in the stream's "
                     '<acquisition> metadata as its LSL app would')
    for flag, default, text in (
            ('--manufacturer', 'MIndGrasp', 'its manufacturer'),
            ('--model', '', "its model (default: 'dataset player: <file>')"),
            ('--reference', '', 'its EEG reference, e.g. Cz (default: none declared)')):
        amplifier.add_argument(flag, default=default, help=text)


def main(args: argparse.Namespace) -> int:
    """Run the player; returns 0, or 1 with a message on bad input."""
    from mindgrasp_eeg.player import DatasetPlayer, concatenate, expand_sources, load_recording

    try:
        recording = concatenate([load_recording(f) for f in expand_sources(args.files)])
        player = DatasetPlayer(recording, args.name, rate=args.rate, loop=args.loop,
                               source_id=args.source_id, stream_type=args.type,
                               manufacturer=args.manufacturer, model=args.model,
                               reference=args.reference)
    except EEGError as exc:
        print(f'mindgrasp eeg play: {exc}', file=sys.stderr)
        return 1
    print(f"Playing {recording.source} as LSL stream '{args.name}' "
          f'({len(recording.channels)} ch @ {recording.rate:g} Hz, '
          f'{recording.duration:.1f} s, {len(recording.annotations)} annotations on '
          f"'{args.name}-markers') at {args.rate:g}x{' in a loop' if args.loop else ''}.",
          flush=True)
    try:
        player.run(duration=args.duration)
    except KeyboardInterrupt:
        pass
    finally:
        print(f'Pushed {player.n_pushed} samples and {player.n_markers} markers.', flush=True)
        player.close()
    return 0
