"""Sweep the set-locations experiment over BCI accuracies (and parameter values): success and
time to grasp against accuracy, with the decoder's realised online accuracy.

    mindgrasp experiment sweep --accuracy 0.3,0.4,0.55,0.7,0.85,1.0 --trials 45 --seed 0
    mindgrasp experiment sweep --accuracy 0.55,0.85 --trials 20 \\
        --param fsm.certainty_threshold=0.3,0.5,0.7 --json

Every point (accuracy x parameter combination) runs the experiment profile's nodes in lock-step
exactly as ``mindgrasp experiment set-locations --subject virtual --accuracy A`` does, into
``<out>/points/<point>/``; the sweep writes sweep.csv, sweep.json, success_vs_accuracy and
time_vs_accuracy (PNG, SVG) and report.md into ``<out>``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

from mindgrasp_experiments.cli import add_common_arguments, check, fail, subject_type

COMMAND = 'sweep'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment sweep``."""
    add_common_arguments(parser, trials=45)
    parser.add_argument('--accuracy', default='0.3,0.4,0.55,0.7,0.85,1.0', metavar='A1,A2,...',
                        help='virtual subject accuracies within (0, 1], comma-separated '
                             '(default 0.3,0.4,0.55,0.7,0.85,1.0)')
    parser.add_argument('--subject', type=subject_type, default='virtual',
                        help='virtual (synthetic EEG, default), eegmmidb:<subject> or a replay '
                             'subject file (.yaml): the same pursuing subject streaming real '
                             'EEG of that EEGMMIDB subject or of the file\'s recordings')
    parser.add_argument('--param', action='append', default=[], metavar='NODE.PARAM=V1,V2,...',
                        help='also vary a parameter of a node (names as in the profile\'s '
                             'parameter files), e.g. fsm.certainty_threshold=0.3,0.5,0.7; '
                             'repeat for more (every combination is run)')


def main(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from mindgrasp_bringup.launch_system import LaunchError
    from mindgrasp_bringup.launch_system.rundir import create_run_dir
    from mindgrasp_eeg import EEGError
    from mindgrasp_experiments import ExperimentError
    from mindgrasp_experiments.cli import subject_launch_args
    from mindgrasp_experiments.engine import lockstep_components
    from mindgrasp_experiments.records import write_records
    from mindgrasp_experiments.report import write_run
    from mindgrasp_experiments.subjects import is_replay
    from mindgrasp_experiments.sweep import (
        apply_params,
        check_params,
        combinations,
        parse_accuracies,
        parse_param,
        point_figures,
        point_name,
        write_sweep,
    )
    from mindgrasp_experiments.workers import run_trials

    try:
        accuracies = parse_accuracies(args.accuracy)
        params = [parse_param(p) for p in args.param]
    except ExperimentError as exc:
        return fail(COMMAND, str(exc))
    # the shared checks of every experiment (our --accuracy is a list, checked above)
    problem = check(argparse.Namespace(**{**vars(args), 'accuracy': None}), COMMAND)
    if problem:
        return fail(COMMAND, problem)
    try:
        out = create_run_dir('sweep', args.out)
    except LaunchError as exc:
        return fail(COMMAND, str(exc))
    if args.subject != 'virtual' and not is_replay(args.subject):
        return fail(COMMAND, f'--subject {args.subject}: a sweep varies the accuracy of a '
                             'pursuing subject; use virtual, eegmmidb:<subject> or a subject '
                             'file (.yaml).')
    try:
        subject_args = subject_launch_args(args.subject, out)
    except (ExperimentError, EEGError) as exc:
        return fail(COMMAND, str(exc))
    log = [] if args.json else None

    def components_at(accuracy: float, params_dir):
        launch_args = {**subject_args, 'protocol': 'set_locations', 'seed': str(args.seed),
                       'trials': '1', 'accuracy': str(accuracy)}
        comps = lockstep_components('experiment', launch_args, params_dir, overlay=args.launch,
                                    log=log.append if log is not None else print)
        for comp in comps:
            if comp.module.endswith('trial_manager_node'):
                comp.ros_args += ['-p', f'stall_timeout:={args.stall_timeout}',
                                  '-p', f'trial_timeout:={args.trial_timeout}']
        return comps

    try:
        # the names of --param are checked against the profile's nodes before any trial runs
        params = check_params(params, components_at(accuracies[0], out / 'params'))
    except ExperimentError as exc:
        return fail(COMMAND, str(exc))
    combos = combinations(params)
    varied = list(combos[0])
    trials = list(range(1, args.trials + 1))
    points = []
    interrupted = False
    wall0 = time.perf_counter()
    sim_total = 0.0
    bar = tqdm(total=len(accuracies) * len(combos) * len(trials), unit='trial',
               disable=args.no_progress, file=sys.stderr, desc='sweep', dynamic_ncols=True)
    try:
        for combo in combos:
            for accuracy in accuracies:
                name = point_name(accuracy, combo)
                point_dir = out / 'points' / name
                comps = apply_params(components_at(accuracy, point_dir / 'params'), combo)
                bar.set_description(f'sweep {name}')
                runs = []
                wall_p = time.perf_counter()
                try:
                    for run in run_trials(comps, trials, seed=args.seed, workers=args.workers,
                                          step_s=args.step, ray=args.ray):
                        runs.append(run)
                        write_records([r.record for r in runs], point_dir)
                        bar.update(1)
                except KeyboardInterrupt:
                    interrupted = True
                records = sorted((r.record for r in runs), key=lambda rec: rec.trial)
                sim = sum(r.sim_s for r in runs)
                sim_total += sim
                if records:
                    wall = time.perf_counter() - wall_p
                    write_run(point_dir, records, {
                        'command': f'mindgrasp experiment sweep (point {name})',
                        'protocol': 'set_locations', 'subject': args.subject, 'seed': args.seed,
                        'accuracy': accuracy, 'params': combo, 'workers': args.workers,
                        'trials_requested': args.trials, 'interrupted': interrupted,
                        'step_s': args.step, 'sim_s': sim, 'wall_s': wall,
                        'cpu_s': sum(r.cpu_s for r in runs),
                        'real_time_factor': sim / wall if wall > 0 else float('nan'),
                        'cpu_s_per_sim_s': (sum(r.cpu_s for r in runs) / sim if sim > 0
                                            else float('nan'))})
                    points.append({'point': name, **point_figures(records, accuracy, combo)})
                if interrupted:
                    raise KeyboardInterrupt
    except KeyboardInterrupt:
        interrupted = True
        print(f'\nInterrupted: writing the {len(points)} point(s) with finished trials.',
              file=sys.stderr)
    finally:
        bar.close()
    wall = time.perf_counter() - wall0
    run_info = {'command': ' '.join(['mindgrasp', 'experiment', COMMAND, *sys.argv[3:]]),
                'subject': args.subject, 'seed': args.seed, 'trials': args.trials,
                'accuracies': accuracies, 'params': {f'{n}.{p}': v for n, p, v in params},
                'workers': args.workers, 'ray': args.ray, 'step_s': args.step, 'wall_s': wall,
                'sim_s': sim_total, 'interrupted': interrupted}
    doc = write_sweep(out, points, varied, run_info)
    print(f'Accuracy sweep: {len(points)} point(s) x {args.trials} trials in {out} '
          f'({wall:.0f} s wall)')
    for p in doc['points']:
        extra = ''.join(f', {k}={p[k]}' for k in varied)
        success = p['success_rate']
        online = p['online_accuracy']
        print(f"  accuracy {p['accuracy']:g}{extra}: success "
              f"{'n/a' if success is None else f'{100 * success:.1f} %'}, online accuracy "
              f"{'n/a' if online is None else f'{100 * online:.1f} %'}")
    print(f"  report: {out / 'report.md'}")
    if args.json:
        print(json.dumps({'points': doc['points'], 'run_dir': str(out),
                          'report_path': str(out / 'report.md'), 'wall_s': wall,
                          'interrupted': interrupted}))
    return 130 if interrupted else 0
