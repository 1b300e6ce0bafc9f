"""Per-subject offline decoding of EEGMMIDB, in the field's terms: our pipelines beside pyRiemann's.

For each subject, task (:data:`~mindgrasp_classifier.evaluation.TASKS`: 4 classes, left/right,
hands/feet, rest/imagery, rest/both hands), pipeline (:func:`pipelines`) and evaluation
(leave-one-run-out, MOABB's within-session 5-fold), one result row with MOABB's columns
(:data:`~mindgrasp_classifier.evaluation.RESULT_COLUMNS`). ``mindgrasp evaluate decoding``
writes them (``results.csv``), a per-subject table (``table.md``) and a plot
(``decoding.png``). ROS-free.

Pipelines: MOABB's three on MOABB's PhysionetMI epochs
(:data:`~mindgrasp_classifier.paradigm.MOABB_PHYSIONET`): ``MDM`` (pyRiemann ``MDM``), ``TS+LR``
(``TangentSpace`` + ``LogisticRegression(C=1)``), ``CSP+LDA`` (pyRiemann ``CSP(nfilter=6)`` +
LDA; two-class tasks only), as MOABB's ``pipelines/MDM.yml``, ``TSLR.yml`` and ``CSP.yml`` build
them; and MIndGrasp's decoder, :mod:`mindgrasp_classifier.pipelines` on the decoder's windows
(:data:`WINDOW_STEP` apart) re-centred on the training mean, a trial decided by its windows' mean
distances: ``MG MDM`` (the default decoder, the online MDM: 1 s windows in 0.5-2.5 s) and
``MG TS+LR replay`` (the replay subjects' decoder,
:data:`~mindgrasp_experiments.subjects.REPLAY_TRAINING`: 2 s windows in 0.5-4 s); on request
``MG FgMDM`` and ``MG TS+LR`` (1 s windows).
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mindgrasp_classifier.evaluation import EVALUATIONS, TASKS, Task
from mindgrasp_classifier.paradigm import MOABB_PHYSIONET, Epoching

__all__ = ['DATASET', 'PUBLISHED', 'PipelineSpec', 'evaluate', 'evaluate_subject',
           'parse_subjects', 'pipelines', 'plot', 'table']

#: MOABB's code of the dataset, so rows can be concatenated with MOABB's own
DATASET = 'PhysionetMotorImagery'
#: MOABB's published PhysionetMI means (docs/source/paper_results.rst of NeuroTechX/moabb; the
#: benchmark of Chevallier et al. 2024, arXiv:2404.15319): WithinSession 5-fold, 109 subjects,
#: ROC-AUC for left vs right hand (the same task as ours); (task, pipeline) -> score
PUBLISHED: dict[tuple[str, str], float] = {
    ('left_right', 'MDM'): 0.5476, ('left_right', 'TS+LR'): 0.6728,
    ('left_right', 'CSP+LDA'): 0.6575,
}


#: changes when the rows of a subject would change: kept rows of another version are recomputed
RESULTS_VERSION = 2     # 2: EEGMMIDB run 12 labelled left/right
#: step between the windows of MIndGrasp's pipelines here (s)
WINDOW_STEP = 0.25
#: the pipelines run unless named: MOABB's three, the decoder's MDM and the replay decoder
DEFAULT_PIPELINES = ('MDM', 'TS+LR', 'CSP+LDA', 'MG MDM', 'MG TS+LR replay')


@dataclass(frozen=True)
class PipelineSpec:
    """A pipeline of the table: how trials are epoched and the estimator fitted on them.

    Attributes
    ----------
    name : str
        Its name in the rows.
    epoching : Epoching
    make : callable
        Returns a new, unfitted scikit-learn classifier on SPD matrices.
    binary_only : bool
        Run on two-class tasks only.
    """

    name: str
    epoching: Epoching
    make: Callable[[], Any]
    binary_only: bool = False


def _mdm() -> Any:
    from pyriemann.classification import MDM

    return MDM(metric='riemann')


def _ts_lr() -> Any:
    from pyriemann.tangentspace import TangentSpace
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline

    return make_pipeline(TangentSpace(metric='riemann'), LogisticRegression(C=1.0))


def _csp_lda() -> Any:
    from pyriemann.spatialfilters import CSP
    from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
    from sklearn.pipeline import make_pipeline

    return make_pipeline(CSP(nfilter=6), LinearDiscriminantAnalysis(solver='svd'))


def _ours(name: str) -> Callable[[], Any]:
    def make() -> Any:
        from mindgrasp_classifier.evaluation import Recentred
        from mindgrasp_classifier.pipelines import make_classifier

        return Recentred(make_classifier(name))
    return make


def pipelines() -> dict[str, PipelineSpec]:
    """Every pipeline of the table, by name (see the module docstring)."""
    from mindgrasp_classifier.paradigm import decoder_epoching
    from mindgrasp_experiments.subjects import REPLAY_TRAINING

    # windows every WINDOW_STEP s, not the decoder's 1/16 s: neighbours 1/16 s apart are 94 %
    # the same samples, and 4 times fewer windows make the table 4 times cheaper
    decoder = decoder_epoching(train_step=WINDOW_STEP)
    replay = decoder_epoching(train_step=WINDOW_STEP, **{
        k: v for k, v in REPLAY_TRAINING.items() if k in ('window', 'tmin', 'tmax')})
    specs = [PipelineSpec('MDM', MOABB_PHYSIONET, _mdm),
             PipelineSpec('TS+LR', MOABB_PHYSIONET, _ts_lr),
             # pyRiemann's multi-class CSP (joint diagonalisation of 64 x 64 matrices) took
             # 77 s per subject for one 4-class evaluation here: two-class tasks only
             PipelineSpec('CSP+LDA', MOABB_PHYSIONET, _csp_lda, binary_only=True),
             PipelineSpec('MG MDM', decoder, _ours('mdm')),
             PipelineSpec('MG FgMDM', decoder, _ours('fgmdm')),
             PipelineSpec('MG TS+LR', decoder, _ours('ts_lr')),
             PipelineSpec('MG TS+LR replay', replay, _ours(REPLAY_TRAINING['pipeline']))]
    return {s.name: s for s in specs}


def parse_subjects(text: str) -> list[int]:
    """``'1-4,6-12'`` -> [1, 2, 3, 4, 6, ..., 12]; raises ValueError naming a bad part."""
    out: list[int] = []
    for part in filter(None, (p.strip() for p in text.split(','))):
        lo, _, hi = part.partition('-')
        if not lo.isdigit() or (hi and not hi.isdigit()):
            msg = f'{part!r} is not a subject number or range; write e.g. 1-4,6-12.'
            raise ValueError(msg)
        first, last = int(lo), int(hi or lo)
        if not 1 <= first <= last <= 109:
            msg = f'{part!r}: EEGMMIDB has subjects 1-109; write e.g. 1-4,6-12.'
            raise ValueError(msg)
        out += [s for s in range(first, last + 1) if s not in out]
    if not out:
        msg = 'No subject given; write e.g. 1-4,6-12.'
        raise ValueError(msg)
    return out


def evaluate_subject(subject: int, *, tasks: Sequence[str] | None = None,
                     pipeline_names: Sequence[str] | None = None,
                     evaluations: Sequence[str] = ('LeaveOneRunOut',),
                     runs: Sequence[int] | None = None, path: str | None = None,
                     seed: int = 42) -> list[dict[str, Any]]:
    """Result rows of one EEGMMIDB subject (the imagery runs on disk).

    Parameters
    ----------
    subject : int
    tasks, pipeline_names : sequence of str, optional
        Default: every task, :data:`DEFAULT_PIPELINES`.
    evaluations : sequence of str
        Keys of :data:`~mindgrasp_classifier.evaluation.EVALUATIONS`.
    runs : sequence of int, optional
        Imagery runs to use (default: 4, 6, 8, 10, 12, 14, those on disk).
    path : str, optional
        Data folder (default ``MNE_DATASETS_EEGBCI_PATH``).
    seed : int
        Fold shuffling of the within-session evaluation.

    Returns
    -------
    list of dict
        One row per task, pipeline and evaluation, in that nesting order.
    """
    from threadpoolctl import threadpool_limits

    from mindgrasp_classifier.evaluation import task as task_of
    from mindgrasp_classifier.paradigm import eegmmidb_runs, trials_of

    specs = pipelines()
    chosen = [specs[n] for n in (pipeline_names or DEFAULT_PIPELINES)]
    the_tasks: list[Task] = [task_of(n) for n in tasks] if tasks else list(TASKS)
    recordings, _present = eegmmidb_runs(subject, runs, path)
    rows: list[dict[str, Any]] = []
    with threadpool_limits(limits=1, user_api='blas'):
        cache: dict[Epoching, Any] = {}
        for spec in chosen:
            if spec.epoching not in cache:
                cache[spec.epoching] = trials_of(recordings, spec.epoching)
        for the_task in the_tasks:
            for spec in chosen:
                if spec.binary_only and len(the_task.classes) > 2:
                    continue
                trials = cache[spec.epoching]
                for name in evaluations:
                    kwargs = {'seed': seed} if name == 'WithinSession' else {}
                    figures = EVALUATIONS[name](spec.make(), trials, the_task, **kwargs)
                    rows.append({**figures, 'subject': subject, 'session': '0',
                                 'channels': len(trials.channels), 'n_sessions': 1,
                                 'dataset': DATASET, 'pipeline': spec.name,
                                 'evaluation': name, 'task': the_task.name})
    return rows


def _subject_job(args: tuple[int, dict[str, Any], Path | None]) -> list[dict[str, Any]]:
    """Rows of one subject, read from ``done`` if it holds them for the same settings, else
    computed (and written there)."""
    subject, kwargs, done = args
    settings = {'version': RESULTS_VERSION, **{k: (list(v) if isinstance(v, (list, tuple))
                                                   else v) for k, v in kwargs.items()}}
    path = None if done is None else done / f'S{subject:03d}.json'
    if path is not None and path.is_file():
        doc = json.loads(path.read_text(encoding='utf-8'))
        if doc.get('settings') == settings:
            return doc['rows']
    rows = evaluate_subject(subject, **kwargs)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix('.tmp')
        tmp.write_text(json.dumps({'settings': settings, 'rows': rows}), encoding='utf-8')
        tmp.replace(path)
    return rows


def evaluate(subjects: Sequence[int], *, jobs: int = 1, done: str | Path | None = None,
             progress: Callable[[int], None] | None = None,
             **kwargs: Any) -> list[dict[str, Any]]:
    """:func:`evaluate_subject` of each subject (``jobs`` processes), rows in subject order;
    ``progress`` is called with the number of subjects done. With ``done`` (a directory), each
    subject's rows are kept there as they finish (``S001.json``) and reused by a rerun with
    the same settings: an interrupted evaluation resumes."""
    folder = None if done is None else Path(done)
    todo = [(s, kwargs, folder) for s in subjects]
    rows: list[dict[str, Any]] = []
    if jobs <= 1 or len(todo) <= 1:
        for i, job in enumerate(todo):
            rows += _subject_job(job)
            if progress is not None:
                progress(i + 1)
        return rows
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for i, part in enumerate(pool.map(_subject_job, todo)):
            rows += part
            if progress is not None:
                progress(i + 1)
    return rows


def _fmt(value: float) -> str:
    return '-' if not math.isfinite(value) else f'{value:.2f}'


def table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown: for each evaluation and task, one row per subject (and the mean and median
    over subjects), one column per pipeline, MOABB's score (ROC-AUC for two classes, accuracy
    for four); ``-``: not measurable (the subject's runs hold too few classes for the split)."""
    out = []
    evaluations = list(dict.fromkeys(r['evaluation'] for r in rows))
    tasks = list(dict.fromkeys(r['task'] for r in rows))
    names = list(dict.fromkeys(r['pipeline'] for r in rows))
    subjects = list(dict.fromkeys(r['subject'] for r in rows))
    index = {(r['evaluation'], r['task'], r['pipeline'], r['subject']): r for r in rows}
    titles = {t.name: t.title for t in TASKS}
    for ev in evaluations:
        for tk in tasks:
            metric = next(r['metric'] for r in rows if r['task'] == tk)
            out.append(f'#### {ev}: {titles.get(tk, tk)} ({metric})\n')
            out.append('| subject | ' + ' | '.join(names) + ' |')
            out.append('|---|' + '---|' * len(names))
            columns: dict[str, list[float]] = {n: [] for n in names}
            for s in subjects:
                cells = []
                for n in names:
                    r = index.get((ev, tk, n, s))
                    v = float(r['score']) if r is not None else math.nan
                    columns[n].append(v)
                    cells.append(_fmt(v))
                out.append(f'| S{int(s):03d} | ' + ' | '.join(cells) + ' |')
            for label, fn in (('mean', np.nanmean), ('median', np.nanmedian)):
                cells = [_fmt(float(fn(v))) if np.isfinite(v).any() else '-'
                         for v in (np.array(columns[n]) for n in names)]
                out.append(f'| **{label}** | ' + ' | '.join(cells) + ' |')
            out.append('')
    return '\n'.join(out)


def plot(rows: Sequence[dict[str, Any]], path: str | Path) -> Path:
    """Per-subject scores (dots) and their median (bar) for each pipeline, one panel per task and
    evaluation; MOABB's published PhysionetMI means (:data:`PUBLISHED`) as crosses. PNG."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    evaluations = list(dict.fromkeys(r['evaluation'] for r in rows))
    tasks = list(dict.fromkeys(r['task'] for r in rows))
    names = list(dict.fromkeys(r['pipeline'] for r in rows))
    chance = {t.name: t.chance for t in TASKS}
    fig, axes = plt.subplots(len(evaluations), len(tasks), squeeze=False,
                             figsize=(3.2 * len(tasks), 3.4 * len(evaluations)), sharey=True)
    for i, ev in enumerate(evaluations):
        for j, tk in enumerate(tasks):
            ax = axes[i][j]
            for k, n in enumerate(names):
                v = np.array([float(r['score']) for r in rows if r['evaluation'] == ev
                              and r['task'] == tk and r['pipeline'] == n], dtype=float)
                v = v[np.isfinite(v)]
                if len(v):
                    ax.bar(k, np.median(v), color='C0' if n.startswith('MG') else 'C7',
                           alpha=0.4)
                    ax.plot(np.full(len(v), k) + np.linspace(-0.2, 0.2, len(v)), v, 'k.',
                            ms=4)
                if (tk, n) in PUBLISHED and ev == 'WithinSession':
                    ax.plot(k, PUBLISHED[(tk, n)], 'rx', ms=9, mew=2)
            ax.axhline(chance.get(tk, 0.5), color='grey', lw=0.8, ls='--')
            metric = next(r['metric'] for r in rows if r['task'] == tk)
            ax.set_title(f'{tk} ({metric})\n{ev}', fontsize=9)
            ax.set_xticks(range(len(names)), names, rotation=60, ha='right', fontsize=7)
            ax.set_ylim(0, 1.02)
    fig.suptitle('EEGMMIDB, per subject: dots = subjects, bar = median, x = MOABB published '
                 'mean (PhysionetMI)', fontsize=9)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
