"""Run the random-locations experiment: one object per trial (random shape and colour) 0.2-0.7 m
from the base; the controller finds, approaches and grasps it autonomously (lock-step, sim time).

    mindgrasp experiment random-locations --trials 507 --seed 0 --workers 2 --json
    mindgrasp experiment random-locations --trials 90 --realism default
"""

from __future__ import annotations

import argparse

from mindgrasp_experiments.cli import add_common_arguments, run_experiment


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment random-locations``."""
    add_common_arguments(parser, trials=507)


def main(args: argparse.Namespace) -> int:
    return run_experiment(args, 'random_locations', 'random-locations')
