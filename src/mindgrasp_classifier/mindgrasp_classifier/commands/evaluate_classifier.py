"""Evaluate an MI model on labelled EEG files or recorded runs (offline, pseudo-online through the
online decoder, or live through LSL)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mindgrasp_classifier.commands._common import (
    add_data_arguments,
    format_report,
    load_from_args,
    print_json,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import MiModel
from mindgrasp_classifier.training import WindowPredictions, evaluate_windows
from mindgrasp_common.mi import REST


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp evaluate classifier``."""
    parser.add_argument('--model', required=True, help='model path (.json written by training)')
    add_data_arguments(parser)
    parser.add_argument('--recenter', choices=('fixed', 'session'), default='fixed',
                        help='re-centre each recording on its own Riemannian mean (session) or '
                             'keep the training reference (fixed, default)')
    parser.add_argument('--pseudo-online', action='store_true',
                        help='also stream each recording through the online decoder and score '
                             'every sliding window by the annotation it lies in (rest windows '
                             'too when the model knows rest): trial, window, per-class and binary '
                             'accuracies, calibration')
    parser.add_argument('--online-recenter', choices=('fixed', 'adaptive'), default=None,
                        help="re-centering of the decoder for --pseudo-online (default: the "
                             "classifier node's default, so windows are decoded as in the loop)")
    parser.add_argument('--plots', metavar='DIR',
                        help='write reliability diagrams (PNG) of the window probabilities to DIR')
    parser.add_argument('--json', action='store_true',
                        help='print the results as one JSON object on the last line')
    parser.add_argument('--no-progress', action='store_true',
                        help='no progress bar for --live (the summary line is printed at the end)')
    parser.add_argument('--live', action='store_true',
                        help='also stream the data in real time through LSL, the acquisition '
                             'node and the classifier node, and score the published predictions')


def _plot(model: MiModel, windows: WindowPredictions, directory: str, what: str) -> Path:
    from mindgrasp_classifier.calibration import label_positions, plot_reliability

    return plot_reliability(model.classifier.logits(windows.distances),
                            label_positions(model.classes, windows.labels), model.temperature,
                            Path(directory) / f'reliability_{windows.scheme}.png',
                            title=f'{what}: {len(windows.labels)} windows\n'
                                  f"{', '.join(model.class_names)}")


def main(args: argparse.Namespace) -> int:
    """Run the evaluation; returns the exit status."""
    plots: list[Path] = []
    try:
        model = MiModel.load(args.model)
        # a model that knows rest is scored on rest epochs too
        recordings = load_from_args(args, rest=REST in model.classes)
        report, windows = evaluate_windows(model, recordings, args.tmin, args.tmax,
                                           recenter=args.recenter)
        if args.plots:
            plots.append(_plot(model, windows, args.plots, 'Offline epochs'))
        online = None
        if args.pseudo_online:
            from mindgrasp_classifier.pseudo_online import node_adaptation, pseudo_online

            adaptation = node_adaptation()
            if args.online_recenter:
                adaptation.recenter = args.online_recenter
            online, online_windows = pseudo_online(model, recordings, args.tmin, args.tmax,
                                                   adaptation=adaptation)
            if args.plots:
                plots.append(_plot(model, online_windows, args.plots, 'Pseudo-online'))
    except ClassifierError as exc:
        print(f'mindgrasp evaluate classifier: {exc}', file=sys.stderr)
        return 1
    print(f'Model {args.model}: {model.pipeline}, classes {model.class_names}, '
          f'{len(model.channels)} channels at {model.rate:g} Hz, {model.window:g} s windows, '
          f'temperature {model.temperature:.3f}')
    cal = report['calibration']
    print(format_report(report, f'Offline ({len(recordings)} recording(s)):'))
    print(f"  calibration (windows): ECE {100 * cal['ece']:.1f} % at T = {cal['temperature']:.2f} "
          f"({100 * cal['ece_uncalibrated']:.1f} % at T = 1)")
    result = dict(report)
    if online is not None:
        from mindgrasp_classifier.pseudo_online import format_pseudo_online

        print(format_pseudo_online(online))
        result['pseudo_online'] = online
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
    if plots:
        print(f"Reliability diagrams: {', '.join(str(p) for p in plots)}")
        result['plots'] = [str(p) for p in plots]
    print(f"Evaluated {report['n_trials']} trial(s) of {len(recordings)} recording(s): accuracy "
          f"{100 * report['accuracy']:.1f} % offline"
          + (f", {100 * online['window']['accuracy']:.1f} % of "
             f"{online['window']['n_windows']} sliding windows pseudo-online"
             if online is not None else '')
          + (f", {100 * result['live']['accuracy']:.1f} % live "
             f"({result['live']['n_predictions']} predictions)" if args.live else '') + '.')
    if args.json:
        print_json(result)
    return 0
