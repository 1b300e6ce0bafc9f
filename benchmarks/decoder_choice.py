"""Which decoder for the closed loop: pipelines, windows and class sets measured pseudo-online.

    MNE_DATASETS_EEGBCI_PATH=../shared/data .venv/bin/python benchmarks/decoder_choice.py [--jobs 2]

EEGMMIDB S001, imagery runs, rest = the T0 epochs. Each setting is calibrated on runs 4 6 and
tested on runs 8 10, and the reverse (calibrate 8 10, test 4 6). Calibration is
``mindgrasp train classifier`` (``training.train``: leave-one-run-out cross-validation, the
temperature fitted on held-out windows); the test is ``mindgrasp evaluate classifier
--pseudo-online`` (``pseudo_online.pseudo_online``: each run streamed through ``MiDecoder``, every
window on the online grid labelled by the annotation it lies in wholly), decoded as the classifier
node does by default (``recenter`` adaptive, its running session mean) and, for comparison, with
the training reference (``fixed``). Epochs 0.5-4.0 s after
the cue for training and trial decisions (T0/T1/T2 last 4.1-4.2 s; a 2 s window needs a longer
epoch than the default 0.5-2.5 s).

Settings: pipelines ``mdm`` and ``ts_lr`` (class-balanced logistic regression), windows 1 s and
2 s (step 1/16 s), classes ``4+rest`` (left, right, both hands, both feet, rest) and
``rest/hands/feet``. Columns: sliding-window accuracy / balanced accuracy, trial accuracy /
balanced accuracy, binary balanced accuracies from the probabilities of the two (groups of)
classes (left vs right, hands vs feet, rest vs imagery, rest vs hands, rest vs feet; ROC AUC in
brackets for the last two), window ECE at T = 1 and at the fitted temperature T.

The last line is a JSON object with every figure.
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any

import numpy as np

SPLITS = {'4 6 -> 8 10': ((4, 6), (8, 10)), '8 10 -> 4 6': ((8, 10), (4, 6))}
CLASS_SETS = {'4+rest': [0, 1, 2, 3, 4], 'rest/hands/feet': [2, 3, 4]}
PIPELINES = ('mdm', 'ts_lr')
WINDOWS = (1.0, 2.0)
EPOCH = (0.5, 4.0)
BINARY = ('left_vs_right', 'hands_vs_feet', 'rest_vs_imagery', 'rest_vs_both_hands',
          'rest_vs_both_feet')


RECENTER = ('adaptive', 'fixed')


def _figures(report: dict[str, Any]) -> dict[str, Any]:
    return {'window_accuracy': report['window']['accuracy'],
            'window_balanced_accuracy': report['window']['balanced_accuracy'],
            'trial_accuracy': report['trial']['accuracy'],
            'trial_balanced_accuracy': report['trial']['balanced_accuracy'],
            'per_class_window': report['window']['per_class'],
            'binary': report['binary'], 'calibration': report['calibration']}


def measure(split: str, classes: str, pipeline: str, window: float) -> list[dict[str, Any]]:
    """Train one setting on the split's calibration runs and score it pseudo-online, once per
    re-centering of :data:`RECENTER`."""
    import dataclasses

    from threadpoolctl import threadpool_limits

    from mindgrasp_classifier.data import load_inputs
    from mindgrasp_classifier.pseudo_online import node_adaptation, pseudo_online
    from mindgrasp_classifier.training import TrainingConfig, train

    cal_runs, test_runs = SPLITS[split]
    t0 = time.perf_counter()
    with threadpool_limits(1):      # one BLAS thread per worker: --jobs sets the parallelism
        cal = load_inputs(eegbci_subject=1, eegbci_runs=cal_runs, rest=True)
        test = load_inputs(eegbci_subject=1, eegbci_runs=test_runs, rest=True)
        cfg = TrainingConfig(pipeline=pipeline, classes=CLASS_SETS[classes], window=window,
                             tmin=EPOCH[0], tmax=EPOCH[1])
        model, cv = train(cal, cfg)
        reports = {rc: pseudo_online(model, test, *EPOCH, adaptation=dataclasses.replace(
            node_adaptation(), recenter=rc))[0] for rc in RECENTER}
    seconds = time.perf_counter() - t0
    return [{'split': split, 'classes': classes, 'pipeline': pipeline, 'window': window,
             'recenter': rc, 'temperature': model.temperature,
             'temperature_source': model.provenance['calibration']['source'],
             'cv': {k: cv.get(k) for k in ('scheme', 'accuracy', 'scored_classes')},
             'cv_optimistic_accuracy': cv.get('optimistic', {}).get('accuracy'),
             **_figures(report), 'seconds': seconds} for rc, report in reports.items()]


def _pct(v: float | None) -> str:
    return '-' if v is None else f'{100 * v:.0f}'


def row(r: dict[str, Any]) -> str:
    """One markdown table row."""
    b = r['binary']
    cells = [r['split'], r['classes'], r['pipeline'], f"{r['window']:g} s",
             f"{_pct(r['window_accuracy'])} / {_pct(r['window_balanced_accuracy'])}",
             f"{_pct(r['trial_accuracy'])} / {_pct(r['trial_balanced_accuracy'])}"]
    for task in BINARY:
        if task not in b:
            cells.append('-')
        elif task.startswith('rest_vs_both'):
            cells.append(f"{_pct(b[task]['balanced_accuracy'])} ({b[task]['auc']:.2f})")
        else:
            cells.append(_pct(b[task]['balanced_accuracy']))
    cal = r['calibration']
    cells += [f"{_pct(cal['ece_uncalibrated'])} -> {_pct(cal['ece'])}",
              f"{r['temperature']:.2f}"]
    return '| ' + ' | '.join(cells) + ' |'


HEADER = ('| calibrate -> test | classes | pipeline | window | window acc / bal % | '
          'trial acc / bal % | L/R | H/F | rest/imag. | rest/hands (AUC) | rest/feet (AUC) | '
          'ECE % T=1 -> T | T |\n|' + '---|' * 13)


def summary(rows: list[dict[str, Any]]) -> str:
    """Mean over the two splits per setting and re-centering, the controller's figures first."""
    lines = ['| classes | pipeline | window | re-centering | rest/hands AUC | rest/feet AUC | '
             'rest/hands bal % | rest/feet bal % | H/F bal % | window bal % | ECE % |',
             '|' + '---|' * 11]
    key = lambda r: (r['classes'], r['pipeline'], r['window'], r['recenter'])  # noqa: E731
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(key(r), []).append(r)

    def mean(rs: list[dict[str, Any]], f: Any) -> float:
        return float(np.mean([f(r) for r in rs]))

    for (classes, pipeline, window, recenter), rs in groups.items():
        lines.append(
            f'| {classes} | {pipeline} | {window:g} s | {recenter} | '
            f"{mean(rs, lambda r: r['binary']['rest_vs_both_hands']['auc']):.2f} | "
            f"{mean(rs, lambda r: r['binary']['rest_vs_both_feet']['auc']):.2f} | "
            f"{_pct(mean(rs, lambda r: r['binary']['rest_vs_both_hands']['balanced_accuracy']))}"
            f" | {_pct(mean(rs, lambda r: r['binary']['rest_vs_both_feet']['balanced_accuracy']))}"
            f" | {_pct(mean(rs, lambda r: r['binary']['hands_vs_feet']['balanced_accuracy']))} | "
            f"{_pct(mean(rs, lambda r: r['window_balanced_accuracy']))} | "
            f"{_pct(mean(rs, lambda r: r['calibration']['ece']))} |")
    return '\n'.join(lines)


def main(argv: list[str] | None = None) -> int:
    """Measure every setting, print the tables and the JSON line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--jobs', type=int, default=1, help='settings measured in parallel (1)')
    args = parser.parse_args(argv)
    settings = list(itertools.product(SPLITS, CLASS_SETS, PIPELINES, WINDOWS))
    t0 = time.perf_counter()
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        rows = [r for rs in pool.map(measure, *zip(*settings, strict=True)) for r in rs]
    print(f'Re-centering {RECENTER[0]} (the classifier node\'s default):')
    print(HEADER)
    for r in rows:
        if r['recenter'] == RECENTER[0]:
            print(row(r))
    print()
    print('Mean over both splits:')
    print(summary(sorted(rows, key=lambda r: (r['classes'], r['pipeline'], r['window']))))
    print(f'\n{len(settings)} settings in {time.perf_counter() - t0:.0f} s')
    print(json.dumps(rows, separators=(',', ':')))
    return 0


if __name__ == '__main__':
    sys.exit(main())
