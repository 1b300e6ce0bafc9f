"""Run the set-locations experiment: 9 objects 0.5 m from the base, a random desired object per
trial, the subject drives the arm through EEG -> classifier -> controller (lock-step, sim time).

    mindgrasp experiment set-locations --trials 160 --subject noise --seed 0 --workers 2
    mindgrasp experiment set-locations --trials 160 --subject virtual --accuracy 0.8
    mindgrasp experiment set-locations --trials 6 --subject oracle --json
"""

from __future__ import annotations

import argparse

from mindgrasp_experiments.cli import add_common_arguments, run_experiment


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment set-locations``."""
    from mindgrasp_common.cli_checks import probability

    add_common_arguments(parser, trials=160)
    parser.add_argument('--subject', choices=['noise', 'virtual', 'oracle'], default='virtual',
                        help='noise (unworn cap, classifier trained on noise), virtual (the '
                             'virtual subject pursues the target at --accuracy) or oracle (its '
                             'intent is the prediction); default virtual')
    parser.add_argument('--accuracy', type=probability, default=0.8,
                        help='virtual subject: probability of imagining the right class '
                             '(default 0.8)')


def main(args: argparse.Namespace) -> int:
    return run_experiment(args, 'set_locations', 'set-locations')
