"""Evaluate an MI model on labelled EEG files or recorded runs (offline, or live through LSL)."""

from __future__ import annotations

import argparse
import sys

from mindgrasp_classifier._cli_common import (
    add_data_arguments,
    format_report,
    load_from_args,
    print_json,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.training import evaluate


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp evaluate classifier``."""
    parser.add_argument('--model', required=True, help='model path (.json written by training)')
    add_data_arguments(parser)
    parser.add_argument('--recenter', choices=('fixed', 'session'), default='fixed',
                        help='re-centre each recording on its own Riemannian mean (session) or '
                             'keep the training reference (fixed, default)')
    parser.add_argument('--json', action='store_true',
                        help='print the results as one JSON object on the last line')
    parser.add_argument('--no-progress', action='store_true',
                        help='no progress bar for --live (the summary line is printed at the end)')
    parser.add_argument('--live', action='store_true',
                        help='also stream the data in real time through LSL, the acquisition '
                             'node and the classifier node, and score the published predictions')


def main(args: argparse.Namespace) -> int:
    """Run the evaluation; returns the exit status."""
    try:
        model = MiModel.load(args.model)
        recordings = load_from_args(args)
        report = evaluate(model, recordings, args.tmin, args.tmax, recenter=args.recenter)
    except ClassifierError as exc:
        print(f'mindgrasp evaluate classifier: {exc}', file=sys.stderr)
        return 1
    print(f'Model {args.model}: {model.pipeline}, classes {model.class_names}, '
          f'{len(model.channels)} channels at {model.rate:g} Hz')
    print(format_report(report, f'Offline ({len(recordings)} recording(s)):'))
    result = dict(report)
    if args.live:
        from mindgrasp_classifier.live import evaluate_live

        try:
            live = evaluate_live(args.model, recordings, args.tmin, args.tmax,
                                 progress=not args.no_progress)
        except ClassifierError as exc:
            print(f'mindgrasp evaluate classifier --live: {exc}', file=sys.stderr)
            return 1
        print(format_report(live, 'Live (LSL -> acquisition node -> classifier node):'))
        diff = 100 * (live['window_accuracy'] - report['window_accuracy'])
        print(f'  live - offline window accuracy: {diff:+.1f} points '
              f"(trial accuracy {100 * (live['accuracy'] - report['accuracy']):+.1f})")
        result['live'] = live
    print(f"Evaluated {report['n_trials']} trial(s) of {len(recordings)} recording(s): accuracy "
          f"{100 * report['accuracy']:.1f} % offline"
          + (f", {100 * result['live']['accuracy']:.1f} % live "
             f"({result['live']['n_predictions']} predictions)" if args.live else '') + '.')
    if args.json:
        print_json(result)
    return 0
