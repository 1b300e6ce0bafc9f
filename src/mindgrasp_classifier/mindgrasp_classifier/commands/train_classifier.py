"""Train the MI classifier on EEG files or recorded runs and write a model file."""

from __future__ import annotations

import argparse
import sys

from mindgrasp_classifier.commands._common import (
    add_data_arguments,
    format_cv_report,
    load_from_args,
    print_json,
)
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import class_index, model_paths
from mindgrasp_classifier.pipelines import PIPELINES
from mindgrasp_classifier.training import COVARIANCE_ESTIMATORS, TrainingConfig, train
from mindgrasp_common.cli_checks import (
    finite_float,
    non_negative_int,
    positive_float,
    positive_int,
)
from mindgrasp_common.mi import REST


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp train classifier``."""
    add_data_arguments(parser)
    parser.add_argument('-o', '--out', required=True, metavar='MODEL',
                        help='model path (writes MODEL.json and MODEL.npz)')
    g = parser.add_argument_group('model')
    g.add_argument('--pipeline', choices=PIPELINES, default='mdm', help='classifier (mdm)')
    g.add_argument('--channels', default='motor',
                   help="'motor' (motor strip, default), 'all', or comma-separated names")
    g.add_argument('--classes', default=None,
                   help='classes to keep, e.g. left_hand,right_hand or rest,both_hands,both_feet '
                        '(default: all in the data; rest implies --rest)')
    g.add_argument('--band', type=finite_float, nargs=2, default=(8.0, 30.0),
                   metavar=('LOW', 'HIGH'), help='band-pass (Hz, 8 30)')
    g.add_argument('--filter-order', type=positive_int, default=4, help='Butterworth order (4)')
    g.add_argument('--window', type=positive_float, default=1.0, help='window length (s, 1.0)')
    g.add_argument('--step', type=positive_float, default=1 / 16,
                   help='online window step (s, 0.0625)')
    g.add_argument('--train-step', type=positive_float, default=1 / 16,
                   help='step of training windows inside an epoch (s, 0.0625)')
    g.add_argument('--estimator', default='oas', choices=COVARIANCE_ESTIMATORS,
                   help='pyRiemann covariance estimator (oas)')
    g.add_argument('--cv', type=non_negative_int, default=5,
                   help='folds of the trial-grouped k-fold, 0 for no cross-validation (5); several '
                        'recordings are cross-validated leave-one-run-out')
    g.add_argument('--min-trials', type=positive_int, default=5, help='fewest trials per class (5)')
    g.add_argument('--seed', type=non_negative_int, default=0,
                   help='seed of the fold shuffling (0)')
    parser.add_argument('--json', action='store_true',
                        help='print the cross-validation report as JSON on the last line')


def main(args: argparse.Namespace) -> int:
    """Run the training; returns the exit status."""
    try:
        classes = None
        if args.classes:
            classes = sorted(class_index(c) for c in args.classes.split(',') if c.strip())
        channels = args.channels if args.channels in ('motor', 'all') else [
            c.strip() for c in args.channels.split(',') if c.strip()]
        rest = args.rest or (classes is not None and REST in classes)
        cfg = TrainingConfig(
            pipeline=args.pipeline, channels=channels, band=tuple(args.band),
            filter_order=args.filter_order, window=args.window, step=args.step,
            train_step=args.train_step, tmin=args.tmin, tmax=args.tmax,
            estimator=args.estimator, classes=classes, rest=rest, cv_folds=max(args.cv, 2),
            min_trials=args.min_trials, seed=args.seed)
        cfg.check()
        recordings = load_from_args(args, rest=rest)
        model, report = train(recordings, cfg, cross_validate=args.cv > 0)
        path = model.save(args.out)
    except ClassifierError as exc:
        print(f'mindgrasp train classifier: {exc}', file=sys.stderr)
        return 1
    print(f'Trained {model.pipeline} on {len(recordings)} recording(s), '
          f'{len(model.channels)} channels at {model.rate:g} Hz: {model.channels}')
    print(f"Classes {model.class_names}; trials {model.provenance['trials_per_class']}.")
    if report:
        print(format_cv_report(report))
    else:
        print('No cross-validation (--cv 0): probabilities are uncalibrated (temperature 1).')
    print(f'Model written to {path} (+ {model_paths(path)[1].name}).')
    if args.json:
        print_json({**report, 'model': str(path), 'channels': model.channels,
                    'pipeline': model.pipeline, 'classes': model.class_names,
                    'temperature': model.temperature})
    return 0
