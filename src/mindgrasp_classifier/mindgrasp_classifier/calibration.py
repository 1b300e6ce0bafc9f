"""Probability calibration: temperature scaling, expected calibration error, reliability diagram.

A model's class probabilities are ``softmax(logits(distances) / T)``
(:meth:`~mindgrasp_classifier.model.MiModel.probabilities`). :func:`fit_temperature` chooses ``T``
by minimising the negative log-likelihood of held-out predictions (Guo et al. 2017, "On
calibration of modern neural networks"); :func:`calibration_bins` and
:func:`expected_calibration_error` measure top-label calibration (confidence = largest
probability); :func:`plot_reliability` draws the reliability diagram.

Distances may be ``inf`` for classes a cross-validation fold did not know (its training data
lacked them): their probability is 0, which is what that fold's model would have said.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.special import log_softmax

from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.pipelines import softmax

#: search range of the temperature (log-spaced); outside it a fit means something else is wrong
TEMPERATURE_BOUNDS = (1e-2, 1e2)
N_BINS = 10


def label_positions(classes: Sequence[int], labels: np.ndarray) -> np.ndarray:
    """Column of each label in a distance/probability matrix ordered as ``classes``.

    ``labels`` shape (n_windows,) of class indices, all in ``classes``; returns shape (n_windows,).
    """
    lookup = {int(c): i for i, c in enumerate(classes)}
    try:
        return np.array([lookup[int(y)] for y in labels], dtype=int)
    except KeyError as exc:
        msg = f'Label {exc.args[0]} is not among the model classes {list(classes)}.'
        raise ClassifierError(msg) from None


def nll(logits: np.ndarray, positions: np.ndarray, temperature: float = 1.0) -> float:
    """Mean negative log-likelihood (nats per window) of the true classes.

    Parameters
    ----------
    logits : ndarray, shape (n_windows, n_classes)
        Classifier logits (``-inf`` for classes a fold did not know).
    positions : ndarray of int, shape (n_windows,)
        Column of the true class (:func:`label_positions`).
    temperature : float
        Logits are divided by it.
    """
    logp = log_softmax(np.asarray(logits, dtype=float) / temperature, axis=1)
    return float(-np.mean(logp[np.arange(len(positions)), positions]))


def fit_temperature(logits: np.ndarray, positions: np.ndarray) -> float:
    """Temperature minimising :func:`nll` of held-out predictions (bounded search on log T).

    Parameters
    ----------
    logits : ndarray, shape (n_windows, n_classes)
    positions : ndarray of int, shape (n_windows,)

    Returns
    -------
    temperature : float
        In :data:`TEMPERATURE_BOUNDS`; 1.0 when there is nothing to fit on.
    """
    logits = np.asarray(logits, dtype=float)
    if len(positions) == 0:
        return 1.0
    lo, hi = np.log(TEMPERATURE_BOUNDS)
    res = minimize_scalar(lambda log_t: nll(logits, positions, float(np.exp(log_t))),
                          bounds=(lo, hi), method='bounded', options={'xatol': 1e-4})
    return float(np.exp(res.x))


def calibration_bins(probabilities: np.ndarray, positions: np.ndarray,
                     n_bins: int = N_BINS) -> dict[str, Any]:
    """Top-label reliability: accuracy against confidence in equal-width confidence bins.

    Parameters
    ----------
    probabilities : ndarray, shape (n_windows, n_classes)
    positions : ndarray of int, shape (n_windows,)
        Column of the true class.
    n_bins : int
        Bins of equal width over [0, 1].

    Returns
    -------
    bins : dict
        ``edges`` (n_bins + 1,), per bin ``count``, ``confidence`` (mean largest probability)
        and ``accuracy`` (fraction whose most probable class is the true one); empty bins have
        ``None`` for both; ``ece``.
    """
    p = np.asarray(probabilities, dtype=float)
    conf = p.max(axis=1)
    correct = np.argmax(p, axis=1) == positions
    edges = np.linspace(0.0, 1.0, n_bins + 1)
    # right-closed bins, the first also holds 0 (confidence is at least 1/n_classes anyway)
    which = np.clip(np.searchsorted(edges, conf, side='left') - 1, 0, n_bins - 1)
    count = np.bincount(which, minlength=n_bins)
    conf_sum = np.bincount(which, weights=conf, minlength=n_bins)
    acc_sum = np.bincount(which, weights=correct.astype(float), minlength=n_bins)
    nonempty = count > 0
    mean_conf = np.where(nonempty, conf_sum / np.maximum(count, 1), np.nan)
    mean_acc = np.where(nonempty, acc_sum / np.maximum(count, 1), np.nan)
    n = max(int(count.sum()), 1)
    ece = float(np.sum(count[nonempty] / n * np.abs(mean_acc[nonempty] - mean_conf[nonempty])))
    return {'edges': edges.tolist(), 'count': count.tolist(),
            'confidence': [None if np.isnan(v) else float(v) for v in mean_conf],
            'accuracy': [None if np.isnan(v) else float(v) for v in mean_acc], 'ece': ece}


def expected_calibration_error(probabilities: np.ndarray, positions: np.ndarray,
                               n_bins: int = N_BINS) -> float:
    """Top-label ECE: count-weighted mean |accuracy - confidence| over ``n_bins`` bins (0..1)."""
    return calibration_bins(probabilities, positions, n_bins)['ece']


def calibration_summary(logits: np.ndarray, positions: np.ndarray,
                        temperature: float) -> dict[str, Any]:
    """NLL and ECE of predictions at temperature 1 (``*_uncalibrated``) and at ``temperature``.

    ``logits`` shape (n_windows, n_classes); ``positions`` shape (n_windows,).
    """
    logits = np.asarray(logits, dtype=float)
    return {
        'temperature': float(temperature), 'n_windows': len(positions),
        'nll_uncalibrated': nll(logits, positions, 1.0),
        'nll': nll(logits, positions, temperature),
        'ece_uncalibrated': expected_calibration_error(softmax(logits), positions),
        'ece': expected_calibration_error(softmax(logits / temperature), positions),
    }


def plot_reliability(logits: np.ndarray, positions: np.ndarray, temperature: float,
                     path: str | Path, title: str = '') -> Path:
    """Reliability diagram (PNG) of uncalibrated (T = 1) and calibrated probabilities.

    Top: accuracy against mean confidence per bin, with the diagonal of perfect calibration;
    bottom: windows per bin. ``logits`` shape (n_windows, n_classes).
    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    logits = np.asarray(logits, dtype=float)
    fig, (ax, ax_n) = plt.subplots(2, 1, figsize=(5.0, 6.0), sharex=True,
                                   gridspec_kw={'height_ratios': (3, 1)})
    ax.plot([0, 1], [0, 1], color='0.6', lw=1, ls='--', label='perfect calibration')
    width = 1.0 / N_BINS
    for t, colour, offset in ((1.0, 'tab:red', -0.22), (temperature, 'tab:blue', 0.22)):
        b = calibration_bins(softmax(logits / t), positions)
        centres = np.asarray(b['edges'][:-1]) + width / 2
        conf = np.array([np.nan if v is None else v for v in b['confidence']])
        acc = np.array([np.nan if v is None else v for v in b['accuracy']])
        ok = ~np.isnan(acc)
        ax.plot(conf[ok], acc[ok], 'o-', color=colour,
                label=f"T = {t:.2f}: ECE {100 * b['ece']:.1f} %")
        ax_n.bar(centres + offset * width, b['count'], width=0.4 * width, color=colour)
    ax.set(xlim=(0, 1), ylim=(0, 1), ylabel='accuracy (most probable class)')
    ax.set_title(title or 'Reliability (top-label)', fontsize=9)
    ax.legend(loc='upper left', fontsize=8)
    ax.grid(alpha=0.3)
    ax_n.set(xlabel='confidence (largest probability)', ylabel='windows')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
