"""The trained MI model: preprocessing settings, re-centering reference and classifier.

A model is two files side by side: ``<name>.json`` (metadata, human-readable) and ``<name>.npz``
(the arrays, loaded with ``allow_pickle=False``). Nothing in either file is executed on load, so a
model from an untrusted source is safe to open; the JSON holds the SHA-256 of the arrays file so a
damaged or swapped file is detected.
"""

from __future__ import annotations

import copy
import hashlib
import json
import platform
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pyriemann.geometry.base import invsqrtm
from pyriemann.geometry.covariance import covariances

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.pipelines import _DistanceClassifier, classifier_from_arrays, softmax
from mindgrasp_classifier.preprocessing import oas_covariances
from mindgrasp_common.errors import CommonError
from mindgrasp_common.mi import CLASS_NAMES, DECODER_CLASS_NAMES  # noqa: F401 - CLASS_NAMES re-exported
from mindgrasp_common.mi import decoder_class_index as mi_class_index
from mindgrasp_common.resources import ResourceNotFoundError, resolve_path

FORMAT = 'mindgrasp-mi-model'
#: the demo model trained by scripts/train_default_classifier.py
DEFAULT_MODEL = 'package://mindgrasp_classifier/models/default_classifier.json'
FORMAT_VERSION = 1
#: Internal unit: microvolts (input in volts), so covariance entries are O(1..1e3).
SCALE_V_TO_UV = 1e6


def class_index(name_or_index: str | int) -> int:
    """Decoder class index from a name (``left_hand``, ``rest``) or index; raises on unknown
    names."""
    try:
        return mi_class_index(name_or_index)
    except CommonError as exc:
        raise ClassifierError(str(exc)) from None


def library_versions() -> dict[str, str]:
    """Versions of the libraries that shape a model's numbers."""
    import importlib.metadata as md

    out = {'python': platform.python_version()}
    for name in ('numpy', 'scipy', 'pyriemann', 'scikit-learn', 'mne', 'mindgrasp-ros'):
        try:
            out[name] = md.version(name)
        except md.PackageNotFoundError:
            out[name] = 'unknown'
    return out


@dataclass
class MiModel:
    """A trained motor-imagery decoder.

    Attributes
    ----------
    classes : list of int
        Class indices the classifier knows (0 left hand ... 3 both feet, 4 rest), sorted.
    channels : list of str
        Channel names the model decodes, in classifier order.
    rate : float
        Sampling rate (Hz) the model was trained at.
    band : (float, float)
        Band-pass edges (Hz).
    filter_order : int
        Butterworth order.
    window : float
        Window length (s).
    step : float
        Window step (s) online.
    pipeline : str
        ``mdm``, ``fgmdm`` or ``ts_lr``.
    classifier : fitted classifier from :mod:`mindgrasp_classifier.pipelines`
        Works on re-centred covariances.
    reference : ndarray, shape (n_channels, n_channels)
        Re-centering reference of the training data (Riemannian mean of its covariances).
    estimator : str
        Covariance estimator (pyRiemann name), ``oas`` by default.
    temperature : float
        Probability calibration: class probabilities are the softmax of the classifier's
        logits divided by this (temperature scaling, fitted on held-out predictions).
    provenance : dict
        Training data, settings and cross-validation results.
    versions : dict
        Library versions at training time.
    answer_pair : dict or None
        The person's scan answer pair ``{name, yes: [class names], no: [class names]}``
        (:mod:`mindgrasp_classifier.answer_pair`); None: not chosen (the controller answers
        ``hands_feet``).
    decision_thresholds : dict or None
        The person's scan decision thresholds ``{confirm, pass, affirm, cancel}`` (nat s).
    gate : dict or None
        The calibration gate (:mod:`mindgrasp_classifier.gate`): ``verdict`` (ready,
        needs_training, not_ready), ``reason``, ``predicted`` (correct_rate, wrong_rate,
        decision_time_s), ``target_wrong_rate``, ``pairs``.
    """

    classes: list[int]
    channels: list[str]
    rate: float
    band: tuple[float, float]
    filter_order: int
    window: float
    step: float
    pipeline: str
    classifier: _DistanceClassifier
    reference: np.ndarray
    estimator: str = 'oas'
    temperature: float = 1.0
    provenance: dict[str, Any] = field(default_factory=dict)
    versions: dict[str, str] = field(default_factory=library_versions)
    answer_pair: dict[str, Any] | None = None
    decision_thresholds: dict[str, float] | None = None
    gate: dict[str, Any] | None = None

    @property
    def class_names(self) -> list[str]:
        """Names of :attr:`classes`."""
        return [DECODER_CLASS_NAMES[c] for c in self.classes]

    def probabilities(self, distances: np.ndarray) -> np.ndarray:
        """Calibrated class probabilities from the classifier's distances.

        ``distances`` has shape (..., n_classes); returns the same shape, rows summing to 1.
        """
        return softmax(self.classifier.logits(distances) / self.temperature)

    def copy(self) -> MiModel:
        """Deep copy (adaptation changes a copy, never the loaded model)."""
        return copy.deepcopy(self)

    # --- maths shared by training, evaluation and the online decoder -------------------------
    def covariances(self, windows: np.ndarray) -> np.ndarray:
        """Shrinkage covariances of filtered windows, shape (n, n_channels, n_channels).

        ``windows`` has shape (n_windows, n_channels, n_samples), in microvolts. OAS uses the
        vectorised :func:`~mindgrasp_classifier.preprocessing.oas_covariances` (equal to
        pyRiemann's); other estimators go through pyRiemann ``covariances``.
        """
        if self.estimator == 'oas':
            return oas_covariances(windows)
        return covariances(windows, estimator=self.estimator)

    @staticmethod
    def recenter(covs: np.ndarray, reference: np.ndarray) -> np.ndarray:
        """Riemannian re-centering ``R^{-1/2} C R^{-1/2}`` (Zanini et al. 2018)."""
        w = invsqrtm(reference)
        return w @ covs @ w

    # --- persistence ----------------------------------------------------------------------
    def metadata(self) -> dict[str, Any]:
        """JSON-serialisable description (everything except the arrays)."""
        return {
            'format': FORMAT,
            'format_version': FORMAT_VERSION,
            'classes': list(map(int, self.classes)),
            'class_names': self.class_names,
            'channels': list(self.channels),
            'rate': float(self.rate),
            'input_unit': 'V',
            'filter': {'type': 'butterworth_bandpass_sos_causal', 'low': float(self.band[0]),
                       'high': float(self.band[1]), 'order': int(self.filter_order)},
            'window': {'length': float(self.window), 'step': float(self.step)},
            'covariance': {'estimator': self.estimator},
            'pipeline': self.pipeline,
            'calibration': {'method': 'temperature_scaling',
                            'temperature': float(self.temperature)},
            'provenance': self.provenance,
            'versions': self.versions,
            **{k: v for k, v in (('answer_pair', self.answer_pair),
                                 ('decision_thresholds', self.decision_thresholds),
                                 ('gate', self.gate)) if v is not None},
        }

    def save(self, path: str | Path) -> Path:
        """Write ``<path>.json`` and ``<path>.npz``; returns the JSON path."""
        json_path, npz_path = model_paths(path)
        json_path.parent.mkdir(parents=True, exist_ok=True)
        arrays = {f'clf_{k}': np.asarray(v) for k, v in self.classifier.to_arrays().items()}
        arrays['reference'] = np.asarray(self.reference, dtype=float)
        with open(npz_path, 'wb') as f:
            np.savez(f, **arrays)
        meta = self.metadata()
        meta['arrays_file'] = npz_path.name
        meta['arrays_sha256'] = hashlib.sha256(npz_path.read_bytes()).hexdigest()
        meta['arrays'] = {k: list(v.shape) for k, v in arrays.items()}
        json_path.write_text(json.dumps(meta, indent=2, default=_json_default) + '\n')
        return json_path

    @classmethod
    def load(cls, path: str | Path) -> MiModel:
        """Read a model written by :meth:`save`; clear errors for missing/corrupt/foreign files.

        ``path``: the .json (or its stem), relative to the working directory, or a data file of
        this package (``models/default_classifier.json``), or ``package://<package>/<path>``.
        """
        json_path = resolve_model_path(path)
        if not json_path.is_file():
            msg = (f'The model file {json_path} does not exist; train one with '
                   '`mindgrasp train classifier` or give the path of an existing model.')
            raise ClassifierError(msg)
        try:
            meta = json.loads(json_path.read_text())
        except (UnicodeDecodeError, json.JSONDecodeError) as exc:
            msg = (f'The model file {json_path} is not valid JSON ({exc}); it is damaged or not a '
                   'MIndGrasp model. Retrain or copy the model again.')
            raise ClassifierError(msg) from None
        if not isinstance(meta, dict) or meta.get('format') != FORMAT:
            msg = (f'{json_path} is not a MIndGrasp MI model (format {FORMAT!r} expected); '
                   'give the .json written by `mindgrasp train classifier`.')
            raise ClassifierError(msg)
        if meta.get('format_version') != FORMAT_VERSION:
            msg = (f'The model {json_path} has format version {meta.get("format_version")}, this '
                   f'software reads version {FORMAT_VERSION}; retrain the model with this version.')
            raise ClassifierError(msg)
        arrays_file = str(meta.get('arrays_file', ''))
        if arrays_file and (Path(arrays_file).name != arrays_file or arrays_file in ('.', '..')
                            or '\\' in arrays_file):
            msg = (f'The model {json_path} names its arrays file {arrays_file!r}, which is not a '
                   'file name beside the .json (a path elsewhere is never read); set '
                   'arrays_file to the .npz file name written with it, or retrain.')
            raise ClassifierError(msg)
        npz_path = json_path.with_name(arrays_file) if arrays_file else json_path
        if not arrays_file or not npz_path.is_file():
            msg = (f'The arrays file {npz_path} of model {json_path} is missing; keep the .npz '
                   'next to the .json (copy both files).')
            raise ClassifierError(msg)
        raw = npz_path.read_bytes()
        if hashlib.sha256(raw).hexdigest() != meta.get('arrays_sha256'):
            msg = (f'The arrays file {npz_path} does not match the checksum in {json_path}; it is '
                   'damaged or belongs to another model. Copy the model files again or retrain.')
            raise ClassifierError(msg)
        try:
            with np.load(npz_path, allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
            _check_arrays(arrays, json_path)
            classes = [int(c) for c in meta['classes']]
            channels = [str(c) for c in meta['channels']]
            clf = classifier_from_arrays(
                meta['pipeline'], np.array(classes),
                {k[4:]: v for k, v in arrays.items() if k.startswith('clf_')})
            model = cls(
                classes=classes, channels=channels, rate=float(meta['rate']),
                band=(float(meta['filter']['low']), float(meta['filter']['high'])),
                filter_order=int(meta['filter']['order']), window=float(meta['window']['length']),
                step=float(meta['window']['step']), pipeline=str(meta['pipeline']),
                classifier=clf, reference=np.asarray(arrays['reference'], dtype=float),
                estimator=str(meta['covariance']['estimator']),
                temperature=float(meta.get('calibration', {}).get('temperature', 1.0)),
                provenance=dict(meta.get('provenance', {})),
                versions=dict(meta.get('versions', {})),
                answer_pair=_optional_dict(meta, 'answer_pair'),
                decision_thresholds=_optional_dict(meta, 'decision_thresholds'),
                gate=_optional_dict(meta, 'gate'))
        except ClassifierError:
            raise
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            msg = (f'The model {json_path} is incomplete or inconsistent ({type(exc).__name__}: '
                   f'{exc}); retrain it with `mindgrasp train classifier`.')
            raise ClassifierError(msg) from None
        if not (np.isfinite(model.temperature) and model.temperature > 0):
            msg = (f'The model {json_path} has calibration temperature {model.temperature}; it '
                   'must be a positive number. Retrain the model or fix calibration.temperature.')
            raise ClassifierError(msg)
        n = len(channels)
        if model.reference.shape != (n, n) or len(set(classes)) != len(classes):
            msg = (f'The model {json_path} lists {n} channels but its arrays have shape '
                   f'{model.reference.shape}; the files are inconsistent, retrain the model.')
            raise ClassifierError(msg)
        return model


def _check_arrays(arrays: dict[str, np.ndarray], json_path: Path) -> None:
    """Refuse arrays no decoder can use: non-finite numbers (NaN, inf) anywhere, and square
    matrices (the reference, class means of shape (n_classes, n_channels, n_channels)) that are
    not symmetric positive definite, which pyriemann rejects only when the first window is
    classified."""
    for key, value in arrays.items():
        if value.dtype.kind in 'fc' and not np.all(np.isfinite(value)):
            msg = (f'The model {json_path} holds non-finite numbers (NaN or inf) in its array '
                   f'{key!r}; the model is damaged: retrain it with `mindgrasp train '
                   'classifier`.')
            raise ClassifierError(msg)
        if value.dtype.kind == 'f' and value.ndim in (2, 3) and value.shape[-1] == \
                value.shape[-2] > 1 and (key == 'reference' or value.ndim == 3):
            try:
                np.linalg.cholesky((value + np.swapaxes(value, -1, -2)) / 2)
                symmetric = np.allclose(value, np.swapaxes(value, -1, -2), rtol=1e-6,
                                        atol=1e-12 * max(1.0, float(np.abs(value).max())))
            except np.linalg.LinAlgError:
                symmetric = False
            if not symmetric:
                msg = (f'The model {json_path} has matrices in its array {key!r} that are not '
                       'symmetric positive definite covariances; the model is damaged: retrain '
                       'it with `mindgrasp train classifier`.')
                raise ClassifierError(msg)


def resolve_model_path(path: str | Path) -> Path:
    """The absolute path of a model's .json, for a path a user gave: with or without the suffix,
    relative to the working directory, a data file of this package (``models/...``) or a
    ``package://<package>/<path>`` URI. The one resolver of model paths: the CLI, the live
    evaluation (which hands the path to a node in another working directory) and the nodes.

    Raises
    ------
    ClassifierError
        A ``package://`` URI whose package or file does not exist.
    """
    if not str(path).strip():
        msg = ('The model path is empty; give the path of a model written by `mindgrasp train '
               'classifier`.')
        raise ClassifierError(msg)
    try:
        resolved = resolve_path(path, 'mindgrasp_classifier', ('.json',))
    except ResourceNotFoundError as exc:
        msg = f'{exc} Give the path of a model written by `mindgrasp train classifier`.'
        raise ClassifierError(msg) from None
    return model_paths(resolved)[0].absolute()


def model_paths(path: str | Path) -> tuple[Path, Path]:
    """(json, npz) paths for a model path given with or without suffix."""
    p = Path(path)
    if p.suffix in ('.json', '.npz'):
        p = p.with_suffix('')
    return p.with_name(p.name + '.json'), p.with_name(p.name + '.npz')


def _optional_dict(meta: dict[str, Any], key: str) -> dict[str, Any] | None:
    value = meta.get(key)
    if value is None:
        return None
    if not isinstance(value, dict):
        msg = f'{key!r} of a model must be a mapping, got {type(value).__name__}'
        raise TypeError(msg)
    return dict(value)


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    msg = f'Cannot store {type(obj).__name__} in model metadata.'
    raise TypeError(msg)
