"""Train the depth shape CNN on simulator images (``mindgrasp train vision``).

Collects ``--n-images`` labelled depth views from the PyBullet simulator (random objects, poses,
colours and distances, camera in pre-final-approach poses), splits them 80/20, trains the 5-layer
CNN, reports the validation accuracy (and the accuracy on an independent test set drawn with
another seed), and saves the model as ``<output>.pt`` (state_dict) + ``<output>.json``.

With ``--realism default`` (or a profile YAML) the images come from a realistic camera (depth
noise, invalid pixels, mount error, lighting, object spread; see mindgrasp_sim.realism), the
validation and test images too, so the reported accuracy is that on noisy depth images.

Example::

    mindgrasp train vision --n-images 600 --seed 0 --output my_models/shape_cnn
    mindgrasp train vision --realism default --n-images 900
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

from mindgrasp_common.cli_checks import non_negative_int, positive_float, positive_int, probability
from mindgrasp_common.resources import resource_path
from mindgrasp_vision._checks import VisionError
from mindgrasp_vision.params import DEFAULT_SHAPE_MODEL

__all__ = ['add_arguments', 'main', 'split_indices']


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp train vision``."""
    parser.add_argument('--n-images', type=positive_int, default=600,
                        help='simulator depth images to collect for training + validation '
                             '(default 600; the paper used about 500)')
    parser.add_argument('--test-images', type=non_negative_int, default=150,
                        help='independent test images, drawn with seed + 1000 (default 150; 0 = '
                             'none)')
    parser.add_argument('--seed', type=non_negative_int, default=0,
                        help='seed of data, split and training')
    parser.add_argument('--epochs', type=positive_int, default=12,
                        help='training epochs (default 12)')
    parser.add_argument('--batch-size', type=positive_int, default=16)
    parser.add_argument('--learning-rate', type=positive_float, default=1e-3)
    parser.add_argument('--val-fraction', type=probability, default=0.2,
                        help='validation share of the collected images (default 0.2)')
    parser.add_argument('--output', default=DEFAULT_SHAPE_MODEL,
                        help=f'model path without suffix (default {DEFAULT_SHAPE_MODEL})')
    parser.add_argument('--dataset', default=None,
                        help='.npz cache of the collected images: read if it exists (as it is, '
                             'whatever --realism), else written')
    parser.add_argument('--realism', default='none',
                        help="camera realism of the training and test images: none (default), "
                             'default or a profile YAML path (mindgrasp_sim.realism)')
    parser.add_argument('--threads', type=positive_int, default=1,
                        help='torch CPU threads (default 1)')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON object with the figures as the last line')
    parser.add_argument('--quiet', action='store_true', help='no per-epoch output')


def split_indices(y: np.ndarray, val_fraction: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Stratified, seeded train/validation split: index arrays (train, val)."""
    rng = np.random.default_rng(seed)
    train, val = [], []
    for c in np.unique(y):
        idx = np.flatnonzero(y == c)
        rng.shuffle(idx)
        n_val = round(len(idx) * val_fraction)
        val.extend(idx[:n_val])
        train.extend(idx[n_val:])
    return np.sort(np.array(train, dtype=int)), np.sort(np.array(val, dtype=int))


def _realism(spec: str) -> object:
    """The realism profile of ``--realism`` (VisionError naming the problem when bad)."""
    from mindgrasp_sim.errors import SimError
    from mindgrasp_sim.realism import RealismProfile

    try:
        return RealismProfile.load(spec)
    except SimError as exc:
        msg = f'--realism {spec}: {exc}'
        raise VisionError(msg) from None


def _confusion(y_true: np.ndarray, y_pred: np.ndarray, n: int) -> list[list[int]]:
    m = np.zeros((n, n), dtype=int)
    np.add.at(m, (y_true, y_pred), 1)
    return m.tolist()


def _collect(n: int, seed: int, cache: str | None, log: Callable[[str], None],
             realism: object = None) -> object:
    from mindgrasp_vision.dataset import ShapeDataset, collect_shape_dataset

    if cache and Path(cache).is_file():
        data = ShapeDataset.load(cache)
        log(f'Loaded {len(data)} images from {cache}.')
        return data
    t0 = time.monotonic()

    def progress(done: int, total: int) -> None:
        if done % 100 == 0 or done == total:
            log(f'  collected {done}/{total} images ({time.monotonic() - t0:.0f} s)')

    data = collect_shape_dataset(n, seed=seed, progress=progress, realism=realism)
    if cache:
        data.save(cache)
    return data


def main(args: argparse.Namespace) -> int:
    """Collect, train, report and save; returns 0, or 1 when the target accuracy is missed."""
    from mindgrasp_vision.shape_cnn import SHAPES, ShapeClassifier

    def log(text: str) -> None:
        print(text, flush=True)

    try:
        if args.n_images < 30:
            msg = f'--n-images must be >= 30 to train and validate, got {args.n_images}.'
            raise VisionError(msg)
        if not 0.05 <= args.val_fraction <= 0.5:
            msg = f'--val-fraction must be in 0.05..0.5, got {args.val_fraction}.'
            raise VisionError(msg)
        realism = _realism(args.realism)
        note = '' if not realism.enabled else f", realism '{realism.name}'"
        log(f'Collecting {args.n_images} depth images from the simulator (seed {args.seed}'
            f'{note})...')
        data = _collect(args.n_images, args.seed, args.dataset, log, realism)
        train, val = split_indices(data.y, args.val_fraction, args.seed)
        log(f'Training the shape CNN on {len(train)} images, validating on {len(val)} '
            f'({args.epochs} epochs, seed {args.seed})...')
        t0 = time.monotonic()
        clf = ShapeClassifier(epochs=args.epochs, batch_size=args.batch_size,
                              learning_rate=args.learning_rate, seed=args.seed,
                              num_threads=args.threads)
        clf.fit(data.x[train], data.y[train], data.x[val], data.y[val], verbose=not args.quiet)
        train_s = time.monotonic() - t0
        pred = clf.predict_proba(data.x[val]).argmax(1)
        val_acc = float(np.mean(pred == data.y[val]))
        per_class = {s: float(np.mean(pred[data.y[val] == i] == i)) for i, s in enumerate(SHAPES)}
        figures = {
            'n_images': len(data), 'n_train': len(train), 'n_val': len(val),
            'seed': args.seed, 'epochs': args.epochs, 'train_time_s': round(train_s, 1),
            'realism': realism.name,
            'val_accuracy': val_acc, 'val_accuracy_by_shape': per_class,
            'val_confusion': _confusion(data.y[val], pred, len(SHAPES)),
        }
        if args.test_images > 0:
            from mindgrasp_vision.dataset import collect_shape_dataset

            log(f'Collecting {args.test_images} independent test images (seed '
                f'{args.seed + 1000})...')
            test = collect_shape_dataset(args.test_images, seed=args.seed + 1000,
                                         realism=realism)
            tpred = clf.predict_proba(test.x).argmax(1)
            figures['test_images'] = len(test)
            figures['test_accuracy'] = float(np.mean(tpred == test.y))
            figures['test_confusion'] = _confusion(test.y, tpred, len(SHAPES))
        output = resource_path('mindgrasp_vision', 'models') / 'shape_cnn' \
            if args.output == DEFAULT_SHAPE_MODEL else Path(args.output)
        pt, js = clf.save(output, training=figures)
    except VisionError as exc:
        print(f'mindgrasp train vision: {exc}', file=sys.stderr)
        return 2
    log(f'Validation accuracy: {100 * val_acc:.1f} % (' + ', '.join(
        f'{s} {100 * a:.1f} %' for s, a in per_class.items()) + '); target >= 95 %.')
    log(f'Validation confusion (rows true, columns predicted, {"/".join(SHAPES)}): '
        f'{figures["val_confusion"]}')
    if 'test_accuracy' in figures:
        log(f'Independent test accuracy ({figures["realism"]} realism): '
            f'{100 * figures["test_accuracy"]:.1f} % on '
            f'{figures["test_images"]} images.')
    log(f'Saved {pt} and {js}.')
    if args.json:
        print(json.dumps({**figures, 'model': str(pt)}))
    return 0 if val_acc >= 0.95 else 1
