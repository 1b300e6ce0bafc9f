# ruff: noqa: N803, N806 - X is scikit-learn's name for the data
"""Riemannian classifiers on covariance matrices, with explicit-array state for safe model files.

Each classifier is a scikit-learn estimator over SPD matrices, shape (n_matrices, n_channels,
n_channels), fitted through pyRiemann, that also exposes per-class ``distances`` (the quantity of
MIndGrasp's certainty, Eq. 1) and ``to_arrays``/``from_arrays`` so a model is stored as plain
numpy arrays (no pickle).

- :class:`MdmClassifier`: minimum distance to Riemannian class means (pyRiemann ``MDM``).
- :class:`FgMdmClassifier`: MDM after geodesic filtering (pyRiemann ``FgMDM``).
- :class:`TsLrClassifier`: tangent space + logistic regression; its "distances" are
  ``-log p(class)``.
"""

from __future__ import annotations

import numpy as np
from pyriemann.classification import MDM
from pyriemann.geometry.base import invsqrtm, logm
from pyriemann.geometry.geodesic import geodesic_riemann
from pyriemann.geometry.mean import mean_logeuclid, mean_riemann
from pyriemann.geometry.tangentspace import tangent_space, untangent_space
from pyriemann.tangentspace import TangentSpace
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.discriminant_analysis import LinearDiscriminantAnalysis
from sklearn.linear_model import LogisticRegression

from mindgrasp_classifier.errors import ClassifierError

PIPELINES = ('mdm', 'fgmdm', 'ts_lr')


def riemann_mean(covs: np.ndarray) -> np.ndarray:
    """pyRiemann's affine-invariant mean of ``covs`` (n, c, c), its gradient descent started at the
    log-Euclidean mean instead of the arithmetic one: the same mean to pyRiemann's tolerance
    (2e-9 apart on EEGMMIDB S002), in 1.3x fewer iterations on raw covariances and 8x fewer on
    re-centred ones (whose mean is the identity), where most of a calibration's time went."""
    covs = np.asarray(covs, dtype=float)
    return mean_riemann(covs, init=mean_logeuclid(covs))


def riemann_distances(covs: np.ndarray, means_invsqrt: np.ndarray) -> np.ndarray:
    """Affine-invariant Riemannian distances of each matrix to each class mean.

    Parameters
    ----------
    covs : ndarray, shape (n_matrices, n_channels, n_channels)
    means_invsqrt : ndarray, shape (n_classes, n_channels, n_channels)
        ``M_k^{-1/2}`` of each class mean (precomputed once per model/update).

    Returns
    -------
    d : ndarray, shape (n_matrices, n_classes)
        ``|| log(M_k^{-1/2} C M_k^{-1/2}) ||_F`` (same as pyRiemann ``distance_riemann``).
    """
    # (n, k, c, c): M_k^{-1/2} C_n M_k^{-1/2}, by broadcasting matmul (fast for small n)
    whitened = means_invsqrt[None] @ covs[:, None] @ means_invsqrt[None]
    eig = np.linalg.eigvalsh(whitened)
    return np.sqrt(np.sum(np.log(np.clip(eig, 1e-300, None)) ** 2, axis=-1))


def certainty(distances: np.ndarray) -> np.ndarray:
    """MIndGrasp certainty (paper Eq. 1): ``mean(d) - min(d)`` over classes.

    Parameters
    ----------
    distances : ndarray, shape (..., n_classes)

    Returns
    -------
    c : ndarray, shape (...)
    """
    d = np.asarray(distances, dtype=float)
    return d.mean(axis=-1) - d.min(axis=-1)


def softmax(logits: np.ndarray) -> np.ndarray:
    """Probabilities from logits along the last axis (shifted by the maximum, so no overflow)."""
    z = np.asarray(logits, dtype=float)
    z = z - z.max(axis=-1, keepdims=True)
    p = np.exp(z)
    return p / p.sum(axis=-1, keepdims=True)


METRICS = ('riemann', 'logeuclid')


def _check_metric(metric: str) -> str:
    if metric not in METRICS:
        msg = f'Unknown metric {metric!r}; choose one of {list(METRICS)}.'
        raise ClassifierError(msg)
    return metric


def _check_covs(X: np.ndarray) -> np.ndarray:
    X = np.asarray(X, dtype=float)
    if X.ndim != 3 or X.shape[1] != X.shape[2]:
        msg = (f'Expected covariance matrices of shape (n_matrices, n_channels, n_channels); '
               f'got {X.shape}. Estimate covariances of the windows first.')
        raise ClassifierError(msg)
    return X


class _DistanceClassifier(ClassifierMixin, BaseEstimator):
    """Common predict/score on top of ``distances``."""

    classes_: np.ndarray

    def distances(self, X: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Class of each matrix: the one at the smallest distance."""
        return self.classes_[np.argmin(self.distances(X), axis=1)]

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """Softmax of :meth:`logits` (for MDM: of ``-d**2``, as pyRiemann's MDM)."""
        return softmax(self.logits(self.distances(X)))

    @staticmethod
    def logits(distances: np.ndarray) -> np.ndarray:
        """Unnormalised log-probabilities from distances, shape as ``distances``: ``-d**2``
        (pyRiemann's MDM ``predict_proba``). A model's temperature divides them."""
        return -(np.asarray(distances, dtype=float) ** 2)

    def certainty(self, X: np.ndarray) -> np.ndarray:
        """Certainty of each matrix, ``mean(d) - min(d)``, shape (n_matrices,)."""
        return certainty(self.distances(X))


class MdmClassifier(_DistanceClassifier):
    """Minimum distance to Riemannian class means (pyRiemann ``MDM``, affine-invariant metric).

    Parameters
    ----------
    metric : {'riemann', 'logeuclid'}
        ``riemann`` (default: the decoder's, the only one a model file stores) or
        ``logeuclid`` (pyRiemann ``MDM(metric='logeuclid')``: log-Euclidean means and
        distances, for offline measurements that fit many models, e.g. decodability).

    Attributes
    ----------
    classes_ : ndarray, shape (n_classes,)
    covmeans_ : ndarray, shape (n_classes, n_channels, n_channels)
    """

    name = 'mdm'
    supports_mean_update = True

    def __init__(self, metric: str = 'riemann') -> None:
        self.metric = metric

    def fit(self, X: np.ndarray, y: np.ndarray) -> MdmClassifier:
        """Fit class means on covariances ``X`` with labels ``y``."""
        X = _check_covs(X)
        mdm = MDM(metric=_check_metric(self.metric)).fit(X, np.asarray(y))
        self.classes_ = mdm.classes_
        self.covmeans_ = np.asarray(mdm.covmeans_, dtype=float)
        self._refresh()
        return self

    def _refresh(self) -> None:
        if self.metric == 'logeuclid':
            self._means_log = logm(self.covmeans_)
        else:
            self._means_invsqrt = invsqrtm(self.covmeans_)

    def _features(self, X: np.ndarray) -> np.ndarray:
        return X

    def distances(self, X: np.ndarray) -> np.ndarray:
        """Distance to each class mean in the classifier's metric, shape (n_matrices,
        n_classes) (log-Euclidean: ``|| log(C) - log(M_k) ||_F``, pyRiemann
        ``distance_logeuclid``)."""
        X = self._features(_check_covs(X))
        if self.metric == 'logeuclid':
            diff = logm(X)[:, None] - self._means_log[None]
            return np.sqrt(np.sum(diff ** 2, axis=(-2, -1)))
        return riemann_distances(X, self._means_invsqrt)

    def update_mean(self, class_position: int, cov: np.ndarray, rate: float) -> None:
        """Move one class mean along the geodesic towards ``cov`` by ``rate`` (0..1)."""
        if self.metric != 'riemann':
            msg = (f'Mean updates move along affine-invariant geodesics; this MDM uses the '
                   f'{self.metric!r} metric. Use MdmClassifier() (metric riemann) online.')
            raise ClassifierError(msg)
        target = self._features(_check_covs(cov[None]))[0]
        self.covmeans_[class_position] = geodesic_riemann(
            self.covmeans_[class_position], target, rate)
        self._means_invsqrt[class_position] = invsqrtm(self.covmeans_[class_position])

    def to_arrays(self) -> dict[str, np.ndarray]:
        """State as named arrays."""
        return {'covmeans': self.covmeans_}

    @classmethod
    def from_arrays(cls, classes: np.ndarray, arrays: dict[str, np.ndarray]) -> MdmClassifier:
        """Rebuild a fitted classifier from :meth:`to_arrays` output."""
        self = cls()
        self.classes_ = np.asarray(classes)
        self.covmeans_ = np.array(arrays['covmeans'], dtype=float)
        self._refresh()
        return self


class FgMdmClassifier(MdmClassifier):
    """MDM after geodesic filtering (FGDA): the same fit as pyRiemann ``FgMDM``.

    Attributes
    ----------
    reference_ : ndarray, shape (n_channels, n_channels)
        Tangent-space reference point of the filter.
    filter_ : ndarray, shape (n_features, n_features)
        Projection in the tangent space (FGDA's ``W``), ``n_features = n(n+1)/2``.
    covmeans_ : ndarray, shape (n_classes, n_channels, n_channels)
        Class means of the filtered matrices.
    """

    name = 'fgmdm'

    def __init__(self) -> None:
        self.metric = 'riemann'     # the filter and the means are affine-invariant

    def fit(self, X: np.ndarray, y: np.ndarray) -> FgMdmClassifier:
        """Fit the geodesic filter and the class means."""
        X, y = _check_covs(X), np.asarray(y)
        # pyRiemann's FgMDM (FGDA then MDM), from public parts so the state is ours to store:
        # tangent space at the Riemannian mean, shrinkage LDA there, the filter projecting onto
        # the discriminant directions, class means of the filtered matrices
        ts = TangentSpace(metric='riemann').fit(X)
        features = ts.transform(X)
        lda = LinearDiscriminantAnalysis(n_components=len(np.unique(y)) - 1, solver='lsqr',
                                         shrinkage='auto').fit(features, y)
        w = lda.coef_
        self.reference_ = np.asarray(ts.reference_, dtype=float)
        self.filter_ = w.T @ np.linalg.pinv(w @ w.T) @ w
        filtered = untangent_space(features @ self.filter_, self.reference_, metric='riemann')
        mdm = MDM(metric='riemann').fit(filtered, y)
        self.classes_ = mdm.classes_
        self.covmeans_ = np.asarray(mdm.covmeans_, dtype=float)
        self._refresh()
        return self

    def _features(self, X: np.ndarray) -> np.ndarray:
        ts = tangent_space(X, self.reference_, metric='riemann')
        return untangent_space(ts @ self.filter_, self.reference_, metric='riemann')

    def to_arrays(self) -> dict[str, np.ndarray]:
        """State as named arrays."""
        return {'covmeans': self.covmeans_, 'reference': self.reference_, 'filter': self.filter_}

    @classmethod
    def from_arrays(cls, classes: np.ndarray, arrays: dict[str, np.ndarray]) -> FgMdmClassifier:
        """Rebuild a fitted classifier from :meth:`to_arrays` output."""
        self = cls()
        self.classes_ = np.asarray(classes)
        self.covmeans_ = np.array(arrays['covmeans'], dtype=float)
        self.reference_ = np.array(arrays['reference'], dtype=float)
        self.filter_ = np.array(arrays['filter'], dtype=float)
        self._refresh()
        return self


class TsLrClassifier(_DistanceClassifier):
    """Tangent space at the Riemannian mean + L2 logistic regression.

    ``distances`` are ``-log p(class | X)``, so the certainty formula applies unchanged.

    Parameters
    ----------
    C : float
        Inverse L2 regularisation strength of the logistic regression.
    class_weight : 'balanced' or None
        ``'balanced'`` (default) weights each class by the inverse of its window count, so the
        probabilities carry no prior from how many epochs of each class the calibration had
        (EEGMMIDB has two to four times as many rest epochs as epochs of one imagery class);
        MDM has no prior either. ``None``: scikit-learn's unweighted fit.
    metric : {'riemann', 'logeuclid'}
        Mean and tangent space: ``riemann`` (default, the only one a model file stores) or
        ``logeuclid`` (pyRiemann's log-Euclidean ones, for offline measurements).
    reference : {'mean', 'identity'}
        Tangent point: the training matrices' mean in ``metric`` (default) or the identity,
        for matrices already re-centred on their mean (decodability re-centres each recording).
    """

    name = 'ts_lr'
    supports_mean_update = False

    def __init__(self, C: float = 1.0, class_weight: str | None = 'balanced',
                 metric: str = 'riemann', reference: str = 'mean') -> None:
        self.C = C
        self.class_weight = class_weight
        self.metric = metric
        self.reference = reference

    def fit(self, X: np.ndarray, y: np.ndarray) -> TsLrClassifier:
        """Fit the reference point and the logistic regression."""
        X = _check_covs(X)
        metric = _check_metric(self.metric)
        if self.reference == 'identity':
            self.reference_ = np.eye(X.shape[-1])
        elif self.reference == 'mean':
            self.reference_ = riemann_mean(X) if metric == 'riemann' else mean_logeuclid(X)
        else:
            msg = f"Unknown reference {self.reference!r}; choose 'mean' or 'identity'."
            raise ClassifierError(msg)
        lr = LogisticRegression(C=self.C, max_iter=2000, class_weight=self.class_weight)
        lr.fit(tangent_space(X, self.reference_, metric=metric), np.asarray(y))
        self.classes_ = lr.classes_
        self.coef_ = np.atleast_2d(lr.coef_).astype(float)
        self.intercept_ = np.atleast_1d(lr.intercept_).astype(float)
        return self

    def _log_proba(self, X: np.ndarray) -> np.ndarray:
        z = tangent_space(_check_covs(X), self.reference_, metric=self.metric) @ self.coef_.T
        z = z + self.intercept_
        if z.shape[1] == 1:  # binary: scikit-learn's single decision function
            z = np.hstack([np.zeros_like(z), z])
        z -= z.max(axis=1, keepdims=True)
        return z - np.log(np.exp(z).sum(axis=1, keepdims=True))

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        """Class probabilities of the logistic regression."""
        return np.exp(self._log_proba(X))

    def distances(self, X: np.ndarray) -> np.ndarray:
        """``-log p(class)``, shape (n_matrices, n_classes)."""
        return -self._log_proba(X)

    @staticmethod
    def logits(distances: np.ndarray) -> np.ndarray:
        """The log-probabilities themselves: ``-distances``."""
        return -np.asarray(distances, dtype=float)

    def to_arrays(self) -> dict[str, np.ndarray]:
        """State as named arrays."""
        return {'reference': self.reference_, 'coef': self.coef_, 'intercept': self.intercept_}

    @classmethod
    def from_arrays(cls, classes: np.ndarray, arrays: dict[str, np.ndarray]) -> TsLrClassifier:
        """Rebuild a fitted classifier from :meth:`to_arrays` output."""
        self = cls()
        self.classes_ = np.asarray(classes)
        self.reference_ = np.array(arrays['reference'], dtype=float)
        self.coef_ = np.array(arrays['coef'], dtype=float)
        self.intercept_ = np.array(arrays['intercept'], dtype=float)
        return self


_CLASSES = {'mdm': MdmClassifier, 'fgmdm': FgMdmClassifier, 'ts_lr': TsLrClassifier}


def make_classifier(name: str) -> _DistanceClassifier:
    """A new, unfitted classifier by pipeline name (``mdm``, ``fgmdm`` or ``ts_lr``)."""
    try:
        return _CLASSES[name]()
    except KeyError:
        msg = f'Unknown pipeline {name!r}; choose one of {list(PIPELINES)}.'
        raise ClassifierError(msg) from None


def classifier_from_arrays(name: str, classes: np.ndarray,
                           arrays: dict[str, np.ndarray]) -> _DistanceClassifier:
    """Rebuild a fitted classifier of pipeline ``name`` from stored arrays."""
    if name not in _CLASSES:
        msg = f'The model names an unknown pipeline {name!r}; known: {list(PIPELINES)}.'
        raise ClassifierError(msg)
    return _CLASSES[name].from_arrays(classes, arrays)


def make_pipeline(name: str = 'mdm', estimator: str = 'oas'):
    """A scikit-learn pipeline on band-passed windows: pyRiemann ``Covariances`` + classifier.

    For use with scikit-learn tools (``cross_val_score``, grid search) on epochs of shape
    (n_windows, n_channels, n_samples); the online decoder uses the same pieces.
    """
    from pyriemann.estimation import Covariances
    from sklearn.pipeline import Pipeline

    return Pipeline([('covariances', Covariances(estimator=estimator)),
                     ('classifier', make_classifier(name))])
