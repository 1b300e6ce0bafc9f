"""Depth shape classifier: a 5-layer CNN that names the object of interest (cube/cylinder/sphere).

As in MIndGrasp, the classifier sees a 128x128 depth image just before the final approach. Unlike
the original (whole image, raw depth), the input is made independent of distance and background:
a square crop round the object's box, depth relative to the object's median depth (scaled by
``depth_range`` and clipped to [-1, 1]) and, when the colour mask is given, everything that is not
the object set to +1 (far). Architecture (original code): 5 x [Conv 32 3x3 + ReLU + MaxPool 2],
Dense 64 + ReLU, Dense 3; Adam, cross-entropy.

The model is saved as a torch ``state_dict`` (``<name>.pt``, loaded with ``weights_only=True``)
plus JSON metadata (``<name>.json``: classes, architecture, preprocessing, training figures).
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

import cv2
import numpy as np

from mindgrasp_common.resources import ResourceNotFoundError, resolve_path
from mindgrasp_vision._checks import VisionError, check_depth

__all__ = ['SHAPES', 'Preprocessing', 'ShapeClassifier', 'build_model', 'preprocess_depth']

#: Output classes, in the order of the network's outputs.
SHAPES: tuple[str, ...] = ('cube', 'cylinder', 'sphere')
FORMAT = 'mindgrasp-shape-cnn'
FORMAT_VERSION = 1


@dataclass(frozen=True)
class Preprocessing:
    """How a depth image becomes a network input (stored with the model).

    Attributes
    ----------
    size : int
        Side of the square input (px).
    depth_range : float
        Relative depth (m) that maps to +/-1.
    margin : float
        Crop margin round the object's box, as a fraction of the box's larger side.
    """

    size: int = 128
    depth_range: float = 0.05
    margin: float = 0.15


def preprocess_depth(depth: np.ndarray, bbox: Sequence[int] | None = None,
                     mask: np.ndarray | None = None,
                     prep: Preprocessing = Preprocessing()) -> np.ndarray:
    """Turn a depth image (and optionally an object's box and mask) into a network input.

    Parameters
    ----------
    depth : ndarray, shape (height, width), dtype float32
        Depth image (m); NaN/inf/<= 0 are no reading.
    bbox : sequence (x, y, w, h) | None
        Object box (px); None uses the whole image (object assumed centred).
    mask : ndarray of bool | None
        The object's pixels, shape (h, w) of ``bbox`` or (height, width) of the image; pixels
        outside it become background (+1).
    prep : Preprocessing
        Input size and scaling.

    Returns
    -------
    x : ndarray, shape (size, size), dtype float32, values in [-1, 1]
    """
    depth = check_depth(depth)
    height, width = depth.shape
    valid = np.isfinite(depth) & (depth > 0)
    full_mask = None
    if mask is not None:
        mask = np.asarray(mask, dtype=bool)
        if mask.shape == (height, width):
            full_mask = mask
        elif bbox is not None and mask.shape == (int(bbox[3]), int(bbox[2])):
            full_mask = np.zeros((height, width), dtype=bool)
            x, y, w, h = (int(v) for v in bbox)
            full_mask[y:y + h, x:x + w] = mask
        else:
            msg = (f'The object mask has shape {mask.shape}, expected the box size or the image '
                   f'size {(height, width)}; pass Detection.mask with Detection.bbox.')
            raise VisionError(msg)
    if bbox is None:
        x0, y0, side_x, side_y = 0, 0, width, height
        cy0, cy1, cx0, cx1 = height * 3 // 8, height * 5 // 8, width * 3 // 8, width * 5 // 8
        ref_pixels = depth[cy0:cy1, cx0:cx1][valid[cy0:cy1, cx0:cx1]]
        if full_mask is not None and (full_mask & valid).any():
            ref_pixels = depth[full_mask & valid]
    else:
        x, y, w, h = (int(v) for v in bbox)
        if w <= 0 or h <= 0:
            msg = f'The object box {tuple(bbox)} is empty; pass a box with w, h > 0 px.'
            raise VisionError(msg)
        side = max(w, h) * (1.0 + 2.0 * prep.margin)
        side_x = side_y = max(2, math.ceil(side))
        x0 = round(x + w / 2.0 - side_x / 2.0)
        y0 = round(y + h / 2.0 - side_y / 2.0)
        sel = valid[y:y + h, x:x + w]
        if full_mask is not None:
            sel = sel & full_mask[y:y + h, x:x + w]
        ref_pixels = depth[y:y + h, x:x + w][sel]
    if ref_pixels.size == 0:
        msg = ('The depth image has no valid reading on the object (all NaN/inf/<= 0); check '
               'that the depth camera sees the object and publishes metres.')
        raise VisionError(msg)
    ref = float(np.median(ref_pixels))
    rel = np.ones((side_y, side_x), dtype=np.float32)
    # copy the part of the crop that lies inside the image; the rest stays background (+1)
    ix0, iy0 = max(0, x0), max(0, y0)
    ix1, iy1 = min(width, x0 + side_x), min(height, y0 + side_y)
    if ix1 > ix0 and iy1 > iy0:
        patch = depth[iy0:iy1, ix0:ix1]
        ok = valid[iy0:iy1, ix0:ix1]
        if full_mask is not None:
            ok = ok & full_mask[iy0:iy1, ix0:ix1]
        vals = np.clip((patch - ref) / prep.depth_range, -1.0, 1.0)
        rel[iy0 - y0:iy1 - y0, ix0 - x0:ix1 - x0] = np.where(ok, vals, 1.0)
    interp = cv2.INTER_AREA if side_x > prep.size else cv2.INTER_LINEAR
    return cv2.resize(rel, (prep.size, prep.size), interpolation=interp).astype(np.float32)


def build_model(size: int = 128, channels: int = 32, n_blocks: int = 5, hidden: int = 64,
                n_classes: int = 3):  # returns torch.nn.Sequential; torch imported lazily
    """The 5-layer CNN: ``n_blocks`` x [Conv ``channels`` 3x3 + ReLU + MaxPool 2], Dense, Dense."""
    import torch.nn as nn

    if size % (2 ** n_blocks):
        msg = (f'The input size {size} px must be divisible by 2**n_blocks = {2 ** n_blocks}; '
               'use 128.')
        raise VisionError(msg)
    layers: list[nn.Module] = []
    in_ch = 1
    for _ in range(n_blocks):
        layers += [nn.Conv2d(in_ch, channels, 3, padding=1), nn.ReLU(), nn.MaxPool2d(2)]
        in_ch = channels
    feat = channels * (size // 2 ** n_blocks) ** 2
    layers += [nn.Flatten(), nn.Linear(feat, hidden), nn.ReLU(), nn.Linear(hidden, n_classes)]
    return nn.Sequential(*layers)


@dataclass
class _Architecture:
    channels: int = 32
    n_blocks: int = 5
    hidden: int = 64


@dataclass
class _Meta:
    classes: list[str] = field(default_factory=lambda: list(SHAPES))
    architecture: dict = field(default_factory=lambda: asdict(_Architecture()))
    preprocessing: dict = field(default_factory=lambda: asdict(Preprocessing()))
    training: dict = field(default_factory=dict)


class ShapeClassifier:
    """Depth-image shape classifier (cube, cylinder, sphere), scikit-learn style.

    Parameters
    ----------
    epochs : int
        Training epochs.
    batch_size : int
        Minibatch size.
    learning_rate : float
        Adam step size.
    seed : int
        Seed of weight initialisation, shuffling and augmentation: same seed, same model.
    num_threads : int
        Torch CPU threads used by fit/predict (1 keeps results bit-identical between machines
        with different core counts).
    prep : Preprocessing
        Input preprocessing.
    """

    def __init__(self, epochs: int = 12, batch_size: int = 16, learning_rate: float = 1e-3,
                 seed: int = 0, num_threads: int = 1, prep: Preprocessing = Preprocessing()
                 ) -> None:
        self.epochs = epochs
        self.batch_size = batch_size
        self.learning_rate = learning_rate
        self.seed = seed
        self.num_threads = num_threads
        self.prep = prep
        self.classes_: list[str] = list(SHAPES)
        self.model_ = None
        self.history_: list[dict] = []
        self.training_: dict = {}

    # ------------------------------------------------------------------ training
    def _check_xy(self, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
        x = np.asarray(x, dtype=np.float32)
        size = self.prep.size
        if x.ndim != 3 or x.shape[1:] != (size, size):
            msg = (f'Network inputs must have shape (n, {size}, {size}), got {x.shape}; build them '
                   'with preprocess_depth().')
            raise VisionError(msg)
        if not np.isfinite(x).all():
            msg = 'Network inputs contain NaN/inf; build them with preprocess_depth().'
            raise VisionError(msg)
        if y is not None:
            y = np.asarray(y)
            if y.shape != (x.shape[0],):
                msg = f'Labels have shape {y.shape}, expected ({x.shape[0]},), one per input.'
                raise VisionError(msg)
            if y.min() < 0 or y.max() >= len(self.classes_):
                msg = (f'Labels must be class indices 0..{len(self.classes_) - 1} '
                       f'({self.classes_}), got {sorted(set(y.tolist()))}.')
                raise VisionError(msg)
        return x

    def fit(self, x: np.ndarray, y: np.ndarray, x_val: np.ndarray | None = None,
            y_val: np.ndarray | None = None, verbose: bool = False) -> ShapeClassifier:
        """Train on preprocessed inputs.

        Parameters
        ----------
        x : ndarray, shape (n, size, size), dtype float32
            Inputs from :func:`preprocess_depth`.
        y : ndarray, shape (n,), dtype int
            Class indices into :data:`SHAPES`.
        x_val, y_val : ndarray | None
            Validation set; its accuracy after each epoch goes to ``history_``.
        verbose : bool
            Print one line per epoch.
        """
        import torch

        x = self._check_xy(x, y)
        y = np.asarray(y, dtype=np.int64)
        if x_val is not None:
            x_val = self._check_xy(x_val, y_val)
        torch.set_num_threads(self.num_threads)
        torch.manual_seed(self.seed)
        gen = torch.Generator().manual_seed(self.seed)
        arch = _Architecture()
        model = build_model(self.prep.size, arch.channels, arch.n_blocks, arch.hidden,
                            len(self.classes_))
        opt = torch.optim.Adam(model.parameters(), lr=self.learning_rate)
        loss_fn = torch.nn.CrossEntropyLoss()
        xt = torch.from_numpy(x).unsqueeze(1)
        yt = torch.from_numpy(y)
        self.history_ = []
        for epoch in range(self.epochs):
            model.train()
            order = torch.randperm(len(xt), generator=gen)
            # augmentation: the three shapes look the same mirrored left-right
            flip = torch.rand(len(xt), generator=gen) < 0.5
            total, correct, loss_sum = 0, 0, 0.0
            for start in range(0, len(xt), self.batch_size):
                idx = order[start:start + self.batch_size]
                xb = xt[idx]
                fb = flip[idx]
                xb = torch.where(fb[:, None, None, None], xb.flip(-1), xb)
                opt.zero_grad()
                out = model(xb)
                loss = loss_fn(out, yt[idx])
                loss.backward()
                opt.step()
                loss_sum += float(loss.detach()) * len(idx)
                correct += int((out.argmax(1) == yt[idx]).sum())
                total += len(idx)
            entry = {'epoch': epoch + 1, 'loss': loss_sum / total,
                     'train_accuracy': correct / total}
            self.model_ = model
            if x_val is not None:
                entry['val_accuracy'] = self.score(x_val, y_val)
            self.history_.append(entry)
            if verbose:
                text = ', '.join(f'{k} {v:.4f}' if isinstance(v, float) else f'{k} {v}'
                                 for k, v in entry.items())
                print(f'  {text}', flush=True)
        model.eval()
        self.model_ = model
        return self

    # ------------------------------------------------------------------ inference
    def _check_fitted(self) -> None:
        if self.model_ is None:
            msg = ('The shape classifier is not trained; call fit() or ShapeClassifier.load() '
                   '(train one with `mindgrasp train vision`).')
            raise VisionError(msg)

    def predict_proba(self, x: np.ndarray) -> np.ndarray:
        """Class probabilities, shape (n, 3), of preprocessed inputs, shape (n, size, size)."""
        import torch

        self._check_fitted()
        x = self._check_xy(x)
        torch.set_num_threads(self.num_threads)
        out = []
        with torch.inference_mode():
            for start in range(0, len(x), 64):
                xb = torch.from_numpy(x[start:start + 64]).unsqueeze(1)
                out.append(torch.softmax(self.model_(xb), dim=1).numpy())
        return np.concatenate(out) if out else np.zeros((0, len(self.classes_)), np.float32)

    def score(self, x: np.ndarray, y: np.ndarray) -> float:
        """Accuracy (0..1) on preprocessed inputs ``x`` with labels ``y``."""
        return float(np.mean(self.predict_proba(x).argmax(1) == np.asarray(y)))

    def predict(self, depth: np.ndarray, bbox: Sequence[int] | None = None,
                mask: np.ndarray | None = None) -> tuple[str, float]:
        """Shape of the object in a depth image.

        Parameters
        ----------
        depth : ndarray, shape (height, width), dtype float32
            Depth image (m).
        bbox : sequence (x, y, w, h) | None
            The object's box (``Detection.bbox``); None takes the whole image (object centred).
        mask : ndarray of bool | None
            The object's pixels (``Detection.mask``), recommended.

        Returns
        -------
        shape : str
            'cube', 'cylinder' or 'sphere'.
        confidence : float
            Softmax probability of that shape (0..1).
        """
        proba = self.predict_proba(preprocess_depth(depth, bbox, mask, self.prep)[None])[0]
        best = int(proba.argmax())
        return self.classes_[best], float(proba[best])

    # ------------------------------------------------------------------ persistence
    def save(self, path: str | Path, training: dict | None = None) -> tuple[Path, Path]:
        """Write ``<path>.pt`` (state_dict) and ``<path>.json`` (metadata); returns both paths."""
        import torch

        self._check_fitted()
        base = Path(path)
        if base.suffix in ('.pt', '.json'):
            base = base.with_suffix('')
        base.parent.mkdir(parents=True, exist_ok=True)
        meta = {
            'format': FORMAT,
            'format_version': FORMAT_VERSION,
            'classes': self.classes_,
            'architecture': asdict(_Architecture()),
            'preprocessing': asdict(self.prep),
            'hyper_parameters': {'epochs': self.epochs, 'batch_size': self.batch_size,
                                 'learning_rate': self.learning_rate, 'seed': self.seed},
            'history': self.history_,
            'training': dict(training or self.training_),
            'torch_version': torch.__version__.split('+')[0],
        }
        pt, js = base.with_suffix('.pt'), base.with_suffix('.json')
        state = {k: v.detach().clone() for k, v in self.model_.state_dict().items()}
        torch.save(state, pt)
        js.write_text(json.dumps(meta, indent=2) + '\n', encoding='utf-8')
        return pt, js

    @classmethod
    def load(cls, path: str | Path, num_threads: int = 1) -> ShapeClassifier:
        """Load a model saved by :meth:`save` (``path`` with or without .pt/.json suffix).

        ``path``: relative to the working directory, a data file of this package
        (``models/shape_cnn``) or ``package://<package>/<path>``.
        """
        import torch

        try:
            base = resolve_path(path, 'mindgrasp_vision', ('.pt', '.json'))
        except ResourceNotFoundError as exc:
            msg = f'{exc} Train a model with `mindgrasp train vision`.'
            raise VisionError(msg) from None
        if base.suffix in ('.pt', '.json'):
            base = base.with_suffix('')
        pt, js = base.with_suffix('.pt'), base.with_suffix('.json')
        for f in (pt, js):
            if not f.is_file():
                msg = (f'The shape model file {f} does not exist; train one with `mindgrasp '
                       'train vision` or set the shape_model parameter to an existing model.')
                raise VisionError(msg)
        try:
            meta = json.loads(js.read_text(encoding='utf-8'))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            msg = f'The shape model metadata {js} is not valid JSON ({exc}); retrain the model.'
            raise VisionError(msg) from exc
        if meta.get('format') != FORMAT or meta.get('format_version') != FORMAT_VERSION:
            msg = (f'{js} is not a {FORMAT} v{FORMAT_VERSION} model (format '
                   f'{meta.get("format")!r} v{meta.get("format_version")}); retrain the model.')
            raise VisionError(msg)
        try:
            state = torch.load(pt, map_location='cpu', weights_only=True)
        except Exception as exc:  # torch raises several types for corrupt/foreign files
            msg = f'Cannot read the shape model weights {pt} ({exc}); retrain the model.'
            raise VisionError(msg) from exc
        hp = meta.get('hyper_parameters', {})
        clf = cls(epochs=hp.get('epochs', 12), batch_size=hp.get('batch_size', 16),
                  learning_rate=hp.get('learning_rate', 1e-3), seed=hp.get('seed', 0),
                  num_threads=num_threads, prep=Preprocessing(**meta['preprocessing']))
        clf.classes_ = list(meta['classes'])
        arch = meta['architecture']
        model = build_model(clf.prep.size, arch['channels'], arch['n_blocks'], arch['hidden'],
                            len(clf.classes_))
        try:
            model.load_state_dict(state)
        except RuntimeError as exc:
            msg = (f'The weights in {pt} do not match the architecture in {js} ({exc}); '
                   'retrain the model.')
            raise VisionError(msg) from exc
        model.eval()
        clf.model_ = model
        clf.history_ = meta.get('history', [])
        clf.training_ = meta.get('training', {})
        return clf
