"""MI classifier figures: EEGMMIDB S001 accuracy, decoding speed, adaptation under drift.

    MNE_DATASETS_EEGBCI_PATH=../shared/data .venv/bin/python benchmarks/classifier.py
    .venv/bin/python benchmarks/classifier.py --skip-accuracy      # timing and adaptation only

1. Accuracy on EEGMMIDB subject S001 (loaded through MNE), chronological split: train on the
   imagery runs 4 and 6, test on 8 and 10; 4 classes, left/right hand (runs 4 -> 8) and both
   hands/both feet (6 -> 10); every pipeline (mdm, fgmdm, ts_lr) on the motor strip (and on all
   64 channels with --all-channels). Trial accuracy = smallest mean distance over the trial's
   1 s windows (step 1/16 s) between cue +0.5 s and +2.5 s; window accuracy per window.
2. Speed of the online decoder (MiDecoder.push with one window step per call, band-pass,
   OAS covariance, re-centering, MDM distances) for 32 and 64 channels at 250 Hz: ms per
   prediction (mean, median, 95th percentile) and predictions per second. Targets: <= 2 ms
   (32 ch), <= 5 ms (64 ch), >= 16 predictions/s.
3. Adaptation on a synthetic session with drift (a changed electrode mixing): online window
   accuracy with a static model, adaptive re-centering, supervised and unsupervised updates.

The last line is a JSON object with every figure.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from mindgrasp_classifier.data import Recording, eegbci_files, load_edf
from mindgrasp_classifier.decoder import AdaptationConfig, MiDecoder
from mindgrasp_classifier.training import (
    TrainingConfig,
    evaluate,
    score_predictions,
    stream_recording,
    train,
)

TASKS = {'4 classes': ([4, 6], [8, 10], None),
         'left/right': ([4], [8], [0, 1]),
         'hands/feet': ([6], [10], [2, 3])}


def synthetic(n_channels: int, rate: float, trials_per_class: int = 6, seed: int = 0,
              drift: np.ndarray | None = None, classes=(0, 1, 2, 3)) -> Recording:
    """Cued recording (V) whose classes differ in spatial covariance; 1 s pre, 3 s cue, 2 s rest."""
    rng = np.random.RandomState(seed)
    mix_rng = np.random.RandomState(1234)
    mixes = {}
    for c in classes:
        q, _ = np.linalg.qr(mix_rng.randn(n_channels, n_channels))
        mixes[c] = q @ np.diag(np.exp(mix_rng.uniform(-1, 1, n_channels)))
    order = rng.permutation(np.repeat(classes, trials_per_class))
    pre, cue, rest = round(rate), round(3 * rate), round(2 * rate)
    blocks, events, t = [], [], 0
    for c in order:
        blocks += [rng.randn(pre, n_channels), rng.randn(cue, n_channels) @ mixes[c].T,
                   rng.randn(rest, n_channels)]
        events.append((t + pre, int(c)))
        t += pre + cue + rest
    data = np.concatenate(blocks) * 10e-6
    if drift is not None:
        data = data @ drift.T
    names = [f'E{i + 1}' for i in range(n_channels)]
    return Recording(data=data, rate=rate, channels=names, events=np.array(events),
                     source=f'synthetic seed {seed}')


def accuracy_table(all_channels: bool) -> list[dict]:
    """Rows of the EEGMMIDB S001 table."""
    runs = {r: load_edf(eegbci_files(1, [r])[0]) for r in (4, 6, 8, 10)}
    rows = []
    for channels in (['motor', 'all'] if all_channels else ['motor']):
        for task, (train_runs, test_runs, classes) in TASKS.items():
            for pipeline in ('mdm', 'fgmdm', 'ts_lr'):
                t0 = time.perf_counter()
                cfg = TrainingConfig(pipeline=pipeline, channels=channels, classes=classes)
                model, _ = train([runs[r] for r in train_runs], cfg, cross_validate=False)
                test = [runs[r] for r in test_runs]
                fixed = evaluate(model, test)
                session = evaluate(model, test, recenter='session')
                rows.append({'task': task, 'pipeline': pipeline, 'channels': channels,
                             'n_channels': len(model.channels), 'n_test_trials': fixed['n_trials'],
                             'accuracy': fixed['accuracy'],
                             'balanced_accuracy': fixed['balanced_accuracy'],
                             'window_accuracy': fixed['window_accuracy'],
                             'accuracy_recentred': session['accuracy'],
                             'chance': fixed['chance'],
                             'seconds': time.perf_counter() - t0})
                r = rows[-1]
                print(f"  {task:<11} {pipeline:<6} {channels:<5} {r['n_channels']:>3} ch  "
                      f"trial {100 * r['accuracy']:5.1f} %  balanced "
                      f"{100 * r['balanced_accuracy']:5.1f} %  window "
                      f"{100 * r['window_accuracy']:5.1f} %  re-centred "
                      f"{100 * r['accuracy_recentred']:5.1f} %  (n={r['n_test_trials']}, "
                      f"chance {100 * r['chance']:.0f} %)", flush=True)
    return rows


def timing(n_channels: int, rate: float = 250.0, seconds: float = 30.0) -> dict:
    """Per-prediction cost of the online decoder."""
    rec = synthetic(n_channels, rate, trials_per_class=5)
    model, _ = train([rec], TrainingConfig(channels='all'), cross_validate=False)
    stream = synthetic(n_channels, rate, trials_per_class=2, seed=1)
    dec = MiDecoder(model, stream.channels, rate)
    step = round(rate * model.step)
    data = stream.data
    n = min(int(seconds * rate), data.shape[0])
    dec.push(data[:round(rate * model.window)], 0)          # fill the first window
    costs = []
    k = round(rate * model.window)
    wall = time.perf_counter()
    while k + step <= n:
        t0 = time.perf_counter()
        out = dec.push(data[k:k + step], k)
        costs.append((time.perf_counter() - t0) / max(len(out), 1))
        k += step
    wall = time.perf_counter() - wall
    ms = np.array(costs) * 1e3
    return {'n_channels': n_channels, 'rate': rate, 'n_predictions': len(ms),
            'ms_mean': float(ms.mean()), 'ms_median': float(np.median(ms)),
            'ms_p95': float(np.percentile(ms, 95)), 'ms_max': float(ms.max()),
            'predictions_per_s': float(len(ms) / wall)}


def adaptation() -> dict:
    """Online accuracy on a drifted session with and without adaptation."""
    n = 12
    rng = np.random.RandomState(7)
    drift = np.diag(np.exp(rng.uniform(-0.7, 0.7, n))) @ (np.eye(n) + 0.25 * rng.randn(n, n))
    model, _ = train([synthetic(n, 128.0, 8, seed=0)], TrainingConfig(channels='all'),
                     cross_validate=False)
    same = synthetic(n, 128.0, 5, seed=11)
    drifted = synthetic(n, 128.0, 5, seed=11, drift=drift)
    cases = {
        'no drift, static': (same, AdaptationConfig(), False),
        'drift, static': (drifted, AdaptationConfig(), False),
        'drift, adaptive re-centering': (drifted, AdaptationConfig(recenter='adaptive'), False),
        'drift, supervised means (rate 0.02)': (
            drifted, AdaptationConfig(mode='supervised', rate=0.02), True),
        'drift, re-centering + supervised': (
            drifted, AdaptationConfig(mode='supervised', rate=0.02, recenter='adaptive'), True),
        'drift, unsupervised means only (rate 0.002)': (
            drifted, AdaptationConfig(mode='unsupervised', rate=0.002, min_certainty=0.25), False),
        'drift, re-centering + unsupervised': (
            drifted, AdaptationConfig(mode='unsupervised', rate=0.002, min_certainty=0.25,
                                      recenter='adaptive'), False),
    }
    out = {}
    for name, (rec, cfg, sup) in cases.items():
        ends, dist = stream_recording(model, rec, cfg, supervised_labels=sup)
        out[name] = score_predictions(model, [rec], [(ends, dist)])['window_accuracy']
        print(f'  {name:<46} window accuracy {100 * out[name]:5.1f} %', flush=True)
    return out


def main(argv: list[str] | None = None) -> int:
    """Print every figure; the last line is JSON."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--skip-accuracy', action='store_true', help='no EEGMMIDB table')
    parser.add_argument('--all-channels', action='store_true',
                        help='also train on all 64 EEGMMIDB channels (slow)')
    parser.add_argument('--seconds', type=float, default=30.0, help='streamed seconds per timing')
    args = parser.parse_args(argv)
    threadpool_limits(limits=1)   # as the classifier node (parameter blas_threads)
    result: dict = {}
    if not args.skip_accuracy:
        print('EEGMMIDB S001, chronological split (train runs 4+6, test 8+10):', flush=True)
        result['accuracy'] = accuracy_table(args.all_channels)
        for task in TASKS:
            rows = [r for r in result['accuracy'] if r['task'] == task]
            best = max(rows, key=lambda r: (r['accuracy'], r['window_accuracy']))
            mdm = next(r for r in rows if r['pipeline'] == 'mdm' and r['channels'] == 'motor')
            print(f"  -> {task}: MDM {100 * mdm['accuracy']:.1f} %, best {best['pipeline']} "
                  f"({best['channels']}) {100 * best['accuracy']:.1f} %")
    print('Online decoding speed (MiDecoder.push, one prediction per 1/16 s step, 250 Hz):',
          flush=True)
    result['timing'] = []
    for n_ch, target in ((32, 2.0), (64, 5.0)):
        t = timing(n_ch, seconds=args.seconds)
        t['target_ms'] = target
        result['timing'].append(t)
        print(f"  {n_ch} channels: {t['ms_mean']:.2f} ms mean, {t['ms_median']:.2f} ms median, "
              f"{t['ms_p95']:.2f} ms p95 per prediction (target <= {target:g} ms); "
              f"{t['predictions_per_s']:.0f} predictions/s (target >= 16)", flush=True)
    print('Adaptation on a session with drift (synthetic, 12 channels):', flush=True)
    result['adaptation'] = adaptation()
    print(json.dumps(result))
    return 0


if __name__ == '__main__':
    sys.exit(main())
