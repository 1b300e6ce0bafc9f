"""Sweep the set-locations experiment over BCI accuracies (and parameter values): success and
time to grasp against accuracy, with the decoder's realised online accuracy.

    mindgrasp experiment sweep --accuracy 0.3,0.4,0.55,0.7,0.85,1.0 --trials 45 --seed 0
    mindgrasp experiment sweep --accuracy 0.55,0.85 --trials 20 \\
        --param fsm.certainty_threshold=0.3,0.5,0.7 --json
    mindgrasp experiment sweep --accuracy 0.7,1.0 --trials 20 \\
        --subject virtual,eegmmidb:1,eegmmidb:2 --seeds 0,1,2 --workers 2

Every point (subject x seed x parameter combination x accuracy) runs the experiment profile's
nodes in lock-step exactly as ``mindgrasp experiment set-locations --subject S --seed N
--accuracy A`` does, into ``<out>/points/<point>/``; the sweep writes sweep.csv, sweep.json,
success_vs_accuracy and time_vs_accuracy (PNG, SVG) and report.md into ``<out>``. With several
subjects or seeds, ``subject`` and ``seed`` are columns of the table like a swept parameter.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from typing import TYPE_CHECKING

from mindgrasp_experiments.cli import add_common_arguments, check, fail, subject_type

if TYPE_CHECKING:
    from mindgrasp_experiments.experiment import Experiment

COMMAND = 'sweep'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment sweep``."""
    add_common_arguments(parser, trials=45)
    parser.add_argument('--accuracy', default='0.3,0.4,0.55,0.7,0.85,1.0', metavar='A1,A2,...',
                        help='virtual subject accuracies within (0, 1], comma-separated '
                             '(default 0.3,0.4,0.55,0.7,0.85,1.0)')
    parser.add_argument('--subject', default='virtual', metavar='S1,S2,...',
                        help='virtual (synthetic EEG, default), eegmmidb:<subject> or a replay '
                             'subject file (.yaml): the same pursuing subject streaming real '
                             'EEG of that EEGMMIDB subject or of the file\'s recordings; '
                             'several, comma-separated, are each a set of points')
    parser.add_argument('--seeds', default=None, metavar='N1,N2,...',
                        help='run every point with each of these seeds (comma-separated; '
                             'instead of --seed)')
    parser.add_argument('--param', action='append', default=[], metavar='NODE.PARAM=V1,V2,...',
                        help='also vary a parameter of a node (names as in the profile\'s '
                             'parameter files), e.g. fsm.certainty_threshold=0.3,0.5,0.7; '
                             'repeat for more (every combination is run)')


def main(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from mindgrasp_eeg import EEGError
    from mindgrasp_experiments import ExperimentError
    from mindgrasp_experiments.cli import experiment_from
    from mindgrasp_experiments.fitted_subject import is_fitted
    from mindgrasp_experiments.subject_launch import subject_launch_args
    from mindgrasp_experiments.subjects import is_replay
    from mindgrasp_experiments.sweep import (
        check_params,
        combinations,
        parse_accuracies,
        parse_param,
        parse_seeds,
        parse_subjects,
        point_figures,
        point_name,
        write_sweep,
    )
    from mindgrasp_launch import LaunchError
    from mindgrasp_launch.rundir import create_run_dir

    try:
        accuracies = parse_accuracies(args.accuracy)
        params = [parse_param(p) for p in args.param]
        subjects = [subject_type(s) for s in parse_subjects(args.subject)]
        seeds = parse_seeds(args.seeds) if args.seeds is not None else [args.seed]
    except argparse.ArgumentTypeError as exc:
        return fail(COMMAND, f'--subject: {exc}.')
    except ExperimentError as exc:
        return fail(COMMAND, str(exc))
    # the shared checks of every experiment (our --accuracy is a list, checked above)
    problem = check(argparse.Namespace(**{**vars(args), 'accuracy': None}), COMMAND)
    if problem:
        return fail(COMMAND, problem)
    try:
        out = create_run_dir('sweep', args.out, option='--out')
    except LaunchError as exc:
        return fail(COMMAND, str(exc))
    (out / 'points').mkdir(exist_ok=True)     # each point's run directory is created in it
    for subject in subjects:
        if subject != 'virtual' and not is_replay(subject) and not is_fitted(subject):
            return fail(COMMAND, f'--subject {subject}: a sweep varies the accuracy of a '
                                 'pursuing subject; use virtual, eegmmidb:<subject> or a subject '
                                 'file (.yaml).')
    try:   # every replay subject is checked and calibrated before the first trial
        subject_args = {subject: subject_launch_args(subject, out) for subject in subjects}
    except (ExperimentError, EEGError) as exc:
        return fail(COMMAND, str(exc))
    log = [] if args.json else None

    # every point is the options' experiment with its own accuracy, subject, seed and params
    base_experiment = experiment_from(argparse.Namespace(**{**vars(args), 'accuracy': None}),
                                      'set_locations')

    def experiment_at(accuracy: float, subject: str, seed: int,
                      combo: dict[str, object]) -> Experiment:
        return dataclasses.replace(base_experiment, accuracy=accuracy, subject=subject,
                                   seed=seed, params=combo)

    try:
        # the names of --param are checked against the profile's nodes before any trial runs
        params = check_params(params, experiment_at(accuracies[0], subjects[0], seeds[0], {})
                              .components(out, subject_args[subjects[0]],
                                          log=log.append if log is not None else print))
    except ExperimentError as exc:
        return fail(COMMAND, str(exc))
    combos = combinations(params)

    def axis_of(subject: str, seed: int) -> dict[str, object]:
        """The point's subject and seed as columns (like a swept parameter), when several."""
        return {**({'subject': subject} if len(subjects) > 1 else {}),
                **({'seed': seed} if len(seeds) > 1 else {})}

    varied = [*axis_of(subjects[0], seeds[0]), *combos[0]]
    points = []
    interrupted = False
    wall0 = time.perf_counter()
    sim_total = 0.0
    points_to_run = [(subject, seed, combo, accuracy) for subject in subjects for seed in seeds
                     for combo in combos for accuracy in accuracies]
    bar = tqdm(total=len(points_to_run) * args.trials, unit='trial',
               disable=args.no_progress, file=sys.stderr, desc='sweep', dynamic_ncols=True)
    try:
        for subject, seed, combo, accuracy in points_to_run:
            axis = axis_of(subject, seed)
            name = point_name(accuracy, {**axis, **combo})
            bar.set_description(f'sweep {name}')
            try:
                results = experiment_at(accuracy, subject, seed, combo).run(
                    out / 'points' / name, subject_args=subject_args[subject],
                    command=f'mindgrasp experiment sweep (point {name})',
                    log=log.append if log is not None else print,
                    warn=lambda line: bar.write(f'mindgrasp experiment {COMMAND}: {line}',
                                                file=sys.stderr),
                    on_trial=lambda runs: bar.update(1))
            except ExperimentError as exc:
                bar.close()
                return fail(COMMAND, str(exc))
            sim_total += results.info['sim_s']
            if results.records:
                points.append({'point': name, **point_figures(
                    results.records, accuracy, {**axis, **combo},
                    results.summary['calibration_accuracy'])})
            if results.interrupted:
                raise KeyboardInterrupt
    except KeyboardInterrupt:
        interrupted = True
        print(f'\nInterrupted: writing the {len(points)} point(s) with finished trials.',
              file=sys.stderr)
    finally:
        bar.close()
    wall = time.perf_counter() - wall0
    run_info = {'command': ' '.join(['mindgrasp', 'experiment', COMMAND, *sys.argv[3:]]),
                'subject': ', '.join(subjects),
                'seed': seeds[0] if len(seeds) == 1 else ', '.join(map(str, seeds)),
                'trials': args.trials,
                'accuracies': accuracies, 'params': {f'{n}.{p}': v for n, p, v in params},
                'workers': args.workers, 'ray': args.ray, 'step_s': args.step, 'wall_s': wall,
                'sim_s': sim_total, 'interrupted': interrupted}
    doc = write_sweep(out, points, varied, run_info)
    print(f'Accuracy sweep: {len(points)} point(s) x {args.trials} trials in {out} '
          f'({wall:.0f} s wall)')
    for p in doc['points']:
        extra = ''.join(f', {k}={p[k]}' for k in varied)
        itr = p['itr_bits_per_min']
        print(f"  accuracy {p['accuracy']:g}{extra}: success {_pct(p['success_rate'])}, "
              f"correct grasp {_pct(p['correct_and_successful_rate'])}, wrong grasp "
              f"{_pct(p['wrong_grasp_rate'])}, ITR "
              f"{'n/a' if itr is None else f'{itr:.2f} bits/min'}, online accuracy "
              f"{_pct(p['online_accuracy'])} (calibration {_pct(p['calibration_accuracy'])})")
    print(f"  report: {out / 'report.md'}")
    if args.json:
        print(json.dumps({'points': doc['points'], 'run_dir': str(out),
                          'report_path': str(out / 'report.md'), 'wall_s': wall,
                          'interrupted': interrupted}))
    return 130 if interrupted else 0


def _pct(rate: float | None) -> str:
    """A rate of the sweep document (None: not defined) in per cent."""
    return 'n/a' if rate is None else f'{100 * rate:.1f} %'


def compare(args: argparse.Namespace, command: str) -> int:
    """``set-locations --param NODE.PARAM=V1,V2``: the comparison is a sweep over those values
    at the subject's accuracy (``mindgrasp experiment sweep``, same records and report)."""
    subject = getattr(args, 'subject', 'virtual')
    if subject in ('noise', 'oracle', 'autonomous'):
        return fail(command, f'--param with several values compares them as a sweep, which '
                             f'varies a pursuing subject; --subject {subject} takes one value '
                             'per --param (run the command once per value).')
    print(f'{command}: several values of --param: comparing them as a sweep at accuracy '
          f'{args.accuracy:g}.', file=sys.stderr)
    return main(argparse.Namespace(**{**vars(args), 'accuracy': str(args.accuracy),
                                      'subject': subject, 'seeds': None}))
