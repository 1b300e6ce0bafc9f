"""Run the set-locations experiment for every subject of a population: calibration and the closed
loop for each, then the table and the figures across subjects.

    mindgrasp experiment population --population docs/populations/eegmmidb_local.yaml \\
        --trials 18 --workers 2
    mindgrasp experiment population --subjects eegmmidb:1,eegmmidb:2 --trials 2 --out runs/pop
    mindgrasp experiment population --population docs/populations/eegmmidb_local.yaml \\
        --trials 18 --ray HEAD:6379

Each subject runs as ``mindgrasp experiment set-locations --subject S`` does, into
``<out>/subjects/<subject>/``; the population writes population.csv, population.json,
population_outcomes and predicted_vs_measured (PNG, SVG) and report.md into ``<out>``. Run again
with the same ``--out`` (and options), a killed population continues with the subject it was
cut off in (:mod:`mindgrasp_experiments.population`).
"""

from __future__ import annotations

import argparse
import json
import sys

from mindgrasp_experiments.cli import add_common_arguments, check, fail

COMMAND = 'population'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment population``."""
    from mindgrasp_common.cli_checks import probability

    # 240 s: the trial timeout the replay subjects are measured with (README)
    add_common_arguments(parser, trials=18, trial_timeout=240.0)
    parser.add_argument('--subjects', default=None, metavar='S1,S2,...',
                        help='replay subjects, comma-separated: eegmmidb:<n> or subject files '
                             '(.yaml), e.g. eegmmidb:1,eegmmidb:2')
    parser.add_argument('--population', action='append', default=[], metavar='FILE',
                        help='a population YAML listing subjects (e.g. '
                             'docs/populations/eegmmidb_local.yaml); repeat for more; with '
                             '--subjects, those come after')
    parser.add_argument('--accuracy', type=probability, default=1.0,
                        help='probability that each subject imagines the right class (the EEG '
                             'is the subject\'s own; default 1.0)')
    parser.add_argument('--gate', choices=('ready', 'any'), default='ready',
                        help='who drives the arm: ready (default) runs the closed loop only for '
                             'subjects whose calibration gate says ready, as the hardware launch '
                             'does; any runs every subject')
    parser.add_argument('--param', action='append', default=[], metavar='NODE.PARAM=V',
                        help='set a parameter of a node for every subject (names as in the '
                             'profile\'s parameter files), e.g. fsm.confirm_threshold=3; a '
                             'population file can set some for one subject')


def main(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from mindgrasp_experiments import ExperimentError
    from mindgrasp_experiments.population import (
        load_population,
        parse_subject_list,
        resolve_subjects,
        run_population,
    )
    from mindgrasp_experiments.sweep import parse_param

    problem = check(args, COMMAND)
    if problem:
        return fail(COMMAND, problem)
    if not args.subjects and not args.population:
        return fail(COMMAND, 'give the subjects: --subjects eegmmidb:1,eegmmidb:2 and/or '
                             '--population FILE (e.g. docs/populations/eegmmidb_local.yaml).')
    try:
        entries = [e for path in args.population for e in load_population(path)]
        if args.subjects:
            entries += [{'subject': s, 'group': '', 'params': {}}
                        for s in parse_subject_list(args.subjects)]
        subjects = resolve_subjects(entries)
        params = {}
        for text in args.param:
            node, name, values = parse_param(text)
            if len(values) > 1:
                return fail(COMMAND, f'--param {text}: a population takes one value per '
                                     'parameter (compare values with mindgrasp experiment '
                                     'sweep).')
            params[f'{node}.{name}'] = values[0]
    except ExperimentError as exc:
        return fail(COMMAND, str(exc))
    out = args.out
    if out is None:
        from mindgrasp_launch.rundir import default_runs_root, utc_stamp

        default_runs_root().mkdir(parents=True, exist_ok=True)
        out = default_runs_root() / f'{utc_stamp()}_population'
    bar = tqdm(total=len(subjects) * args.trials, unit='trial', disable=args.no_progress,
               file=sys.stderr, desc=COMMAND, dynamic_ncols=True)

    def on_subject(subject, status: str) -> None:
        bar.set_description(f'{COMMAND} {subject.label} ({status})')
        if status in ('resumed', 'failed', 'gated'):
            bar.update(args.trials)

    def warn(line: str) -> None:
        bar.write(f'mindgrasp experiment {COMMAND}: {line}', file=sys.stderr)

    log: list[str] = []
    try:
        results = run_population(
            subjects, out, trials=args.trials, seed=args.seed, accuracy=args.accuracy,
            workers=args.workers, params=params, ray=args.ray, robot=args.robot,
            realism=args.realism, launch=args.launch, step_s=args.step,
            trial_timeout_s=args.trial_timeout, stall_timeout_s=args.stall_timeout,
            command=' '.join(['mindgrasp', 'experiment', COMMAND, *sys.argv[3:]]),
            log=log.append if args.json else lambda line: bar.write(line, file=sys.stderr),
            warn=warn, on_subject=on_subject, on_trial=lambda: bar.update(1), gate=args.gate)
    except ExperimentError as exc:
        bar.close()
        return fail(COMMAND, str(exc))
    finally:
        bar.close()
    fig = results.figures
    print(f"Population: {fig['subjects_run']} of {fig['subjects']} subjects x {args.trials} "
          f"trials in {results.out} ({results.info['wall_s'] / 60:.1f} min wall)")
    for r in results.rows:
        if not r.get('trials'):
            print(f"  {r['label']}: {r['status']}")
            continue
        print(f"  {r['label']}: correct {r['correct_count']}/{r['trials']}, wrong grasp "
              f"{r['wrong_grasp_count']}, no grasp {r['no_grasp_count']}; answer pair "
              f"{r.get('answer_pair') or '-'}, gate {r.get('gate_verdict') or '-'}")
    median = fig['correct_rate']['median']
    pooled = fig['pooled_wrong_grasp_rate']
    print(f"  median correct {'-' if median is None else f'{100 * median:.1f} %'}, pooled "
          f"wrong grasps {'-' if pooled is None else f'{100 * pooled:.1f} %'}, subjects at "
          f">= 50 % correct {_pct(fig['share_at_least_half_correct'])}")
    print(f"  report: {results.out / 'report.md'}")
    if args.json:
        doc = json.loads((results.out / 'population.json').read_text(encoding='utf-8'))
        print(json.dumps({**doc, 'run_dir': str(results.out),
                          'report_path': str(results.out / 'report.md'),
                          'interrupted': results.interrupted}))
    if results.interrupted:
        return 130
    return 1 if fig['subjects_run'] < fig['subjects'] else 0


def _pct(rate: float | None) -> str:
    return '-' if rate is None else f'{100 * rate:.1f} %'
