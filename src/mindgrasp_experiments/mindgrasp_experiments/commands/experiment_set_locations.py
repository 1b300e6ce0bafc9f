"""Run the set-locations experiment: 9 objects 0.5 m from the base, a random desired object per
trial, the subject drives the arm through EEG -> classifier -> controller (lock-step, sim time).

    mindgrasp experiment set-locations --trials 160 --subject noise --seed 0 --workers 2
    mindgrasp experiment set-locations --trials 160 --subject virtual --accuracy 0.8
    mindgrasp experiment set-locations --trials 6 --subject oracle --json
    mindgrasp experiment set-locations --trials 10 --subject eegmmidb:1 --accuracy 0.9
    mindgrasp experiment set-locations --trials 30 \
        --subject virtual:docs/subjects/eegmmidb_s001_virtual.yaml
    mindgrasp experiment set-locations --trials 90 --subject virtual --realism default
    mindgrasp experiment set-locations --trials 18 --subject eegmmidb:1 \
        --param fsm.paradigm=paper,scan
"""

from __future__ import annotations

import argparse

from mindgrasp_experiments.cli import (
    add_common_arguments,
    add_param_argument,
    run_experiment,
    subject_type,
)
from mindgrasp_experiments.commands import experiment_sweep


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment set-locations``."""
    from mindgrasp_common.cli_checks import probability

    add_common_arguments(parser, trials=160)
    parser.add_argument('--subject', type=subject_type, default='virtual',
                        help='noise (unworn cap, classifier trained on noise), virtual (the '
                             'virtual subject pursues the target at --accuracy), oracle (its '
                             'intent is the prediction), eegmmidb:<subject> or a replay subject '
                             'file (.yaml; it pursues the target with real EEG of that EEGMMIDB '
                             'subject or of the file\'s recordings), virtual:FILE.yaml (the '
                             'virtual subject on a head fitted by mindgrasp eeg fit-virtual, '
                             'calibrated on it first); default virtual')
    parser.add_argument('--accuracy', type=probability, default=0.8,
                        help='virtual subject: probability of imagining the right class '
                             '(default 0.8)')
    add_param_argument(parser)


def main(args: argparse.Namespace) -> int:
    return run_experiment(args, 'set_locations', 'set-locations', compare=experiment_sweep.compare)
