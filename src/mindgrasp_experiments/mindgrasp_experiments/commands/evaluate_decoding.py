"""Offline decoding of EEGMMIDB subjects, per subject, in MOABB's terms: our decoder's pipelines
beside pyRiemann's MDM, TS+LR and CSP+LDA, for 4 classes and each binary pair.

    mindgrasp evaluate decoding --subjects 1-4,6-12 --out runs/decoding

Writes results.csv (MOABB's columns: score, time, samples, subject, session, channels,
n_sessions, dataset, pipeline, evaluation; then task, metric, balanced_accuracy, n_folds,
n_trials), table.md (one table per evaluation and task, a row per subject) and decoding.png.
Each subject's rows are kept in subjects/S001.json as it finishes: the same command again
resumes an interrupted evaluation. Reads the runs on disk only (MNE_DATASETS_EEGBCI_PATH);
nothing is downloaded.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

PROG = 'mindgrasp evaluate decoding'


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp evaluate decoding``."""
    from mindgrasp_classifier.evaluation import EVALUATIONS, TASKS
    from mindgrasp_common.cli_checks import bounded_int, non_negative_int

    parser.add_argument('--subjects', required=True,
                        help='EEGMMIDB subjects, e.g. 1-4,6-12 (their imagery runs on disk)')
    parser.add_argument('--tasks', default=','.join(t.name for t in TASKS),
                        help='comma-separated tasks (default: all): '
                             + ', '.join(t.name for t in TASKS))
    parser.add_argument('--pipelines', default=None,
                        help='comma-separated pipelines: MDM, TS+LR, CSP+LDA (two-class tasks), '
                             'MG MDM, MG TS+LR replay (these five by default), MG FgMDM, '
                             'MG TS+LR')
    parser.add_argument('--evaluations', default='LeaveOneRunOut,WithinSession',
                        help='comma-separated: ' + ', '.join(EVALUATIONS)
                             + ' (default: both)')
    parser.add_argument('--runs', default=None,
                        help='imagery runs to use, e.g. 4,6,8 (default: 4,6,8,10,12,14, those '
                             'on disk)')
    parser.add_argument('--seed', type=non_negative_int, default=42,
                        help='seed of the within-session folds (default 42)')
    parser.add_argument('--jobs', type=bounded_int(1, 256), default=1,
                        help='subjects in parallel, 1-256 (default 1)')
    parser.add_argument('--out', required=True, help='output directory')


def _names(text: str | None, known: list[str], what: str) -> list[str] | None:
    if text is None:
        return None
    names = [n.strip() for n in text.split(',') if n.strip()]
    bad = [n for n in names if n not in known]
    if bad or not names:
        msg = f'unknown {what} {", ".join(bad) or "(none given)"}; choose from {", ".join(known)}.'
        raise ValueError(msg)
    return names


def main(args: argparse.Namespace) -> int:
    """Run the evaluation; 0, or 2 with one line on a bad argument or missing data."""
    from mindgrasp_classifier.errors import ClassifierError
    from mindgrasp_classifier.evaluation import EVALUATIONS, TASKS, write_results
    from mindgrasp_experiments.decoding import (
        evaluate,
        parse_subjects,
        pipelines,
        plot,
        table,
    )

    try:
        subjects = parse_subjects(args.subjects)
        tasks = _names(args.tasks, [t.name for t in TASKS], 'task')
        names = _names(args.pipelines, list(pipelines()), 'pipeline')
        evaluations = _names(args.evaluations, list(EVALUATIONS), 'evaluation')
        runs = [int(r) for r in args.runs.split(',')] if args.runs else None
        if args.jobs < 1:
            raise ValueError(f'--jobs {args.jobs}: give 1 or more.')
    except ValueError as exc:
        print(f'{PROG}: {exc}', file=sys.stderr)
        return 2
    from tqdm import tqdm

    bar = tqdm(total=len(subjects), desc='subjects', file=sys.stderr, disable=None, leave=False)
    try:
        rows = evaluate(subjects, jobs=args.jobs, done=Path(args.out) / 'subjects',
                        tasks=tasks, pipeline_names=names,
                        evaluations=evaluations, runs=runs, seed=args.seed,
                        progress=lambda n: bar.update(n - bar.n))
    except ClassifierError as exc:
        bar.close()
        print(f'{PROG}: {exc}', file=sys.stderr)
        return 2
    bar.close()
    out = Path(args.out)
    try:
        csv_path = write_results(rows, out / 'results.csv')
        md = out / 'table.md'
        md.write_text(table(rows), encoding='utf-8')
        png = plot(rows, out / 'decoding.png')
    except OSError as exc:
        print(f'{PROG}: cannot write into {out} ({exc.strerror or exc}); choose a writable '
              '--out.', file=sys.stderr)
        return 2
    print(table(rows))
    print(f'{len(rows)} rows for {len(subjects)} subject(s): {csv_path}, {md}, {png}')
    return 0
