"""ROS parameters of the classifier node (``config/param/classifier.yaml``; tests/ros/
test_node_params.py checks the file against the defaults)."""

from __future__ import annotations

from dataclasses import dataclass

from mindgrasp_classifier.decoder import ADAPT_MODES, RECENTER_MODES
from mindgrasp_classifier.errors import ClassifierError
from mindgrasp_classifier.model import CLASS_NAMES, DEFAULT_MODEL
from mindgrasp_ros.params import param

__all__ = ['ClassifierParams']


@dataclass
class ClassifierParams:
    """ROS parameters of the classifier node (read-only: the model and decoder are built at
    start; restart the node to change them)."""

    model: str = param(DEFAULT_MODEL, 'model written by `mindgrasp train classifier` (.json next '
                       'to its .npz): a path or a package:// URI')
    classes: list[str] = param(list(CLASS_NAMES), 'classes the application needs; a model with '
                               'other classes (besides rest) is refused ([] = any)')
    adaptation: str = param('none', 'adaptive class means', choices=ADAPT_MODES)
    adaptation_rate: float = param(0.005, 'geodesic step of an adaptive update per window',
                                   min=0.0, max=1.0)
    min_certainty: float = param(0.5, 'certainty needed for an unsupervised update', min=0.0,
                                 max=1000.0)
    recenter: str = param('adaptive', 'Riemannian re-centering: the training reference or the '
                          "session's running mean", choices=RECENTER_MODES)
    # slow forgetting (horizon ~2 min at 16 windows/s): a shorter memory follows the class mix of
    # the last seconds (a scan answers 'no' far more often than 'yes') instead of the session
    recenter_rate: float = param(0.0005, 'smallest weight of a new window in the running session '
                                 'mean', min=0.0, max=1.0)
    recenter_prior: float = param(60.0, 'adaptive re-centering starts from the training '
                                  'reference weighted as this many seconds of windows',
                                  unit='s', min=0.0, max=3600.0)
    label_tmin: float = param(0.5, 'windows in [cue + label_tmin, cue + label_tmax] get the '
                              "cue's class for supervised adaptation", unit='s', min=-60.0,
                              max=60.0)
    label_tmax: float = param(2.5, 'end of the labelled span after a cue', unit='s', min=-60.0,
                              max=60.0)
    flat_threshold: float = param(1e-8, 'filtered channel std below this = flat electrode',
                                  unit='V', min=0.0, max=1.0)
    status_period: float = param(1.0, 'between /bci/status messages', unit='s', min=0.01,
                                 max=3600.0)
    frame_id: str = param('eeg', 'frame_id of the predictions')
    blas_threads: int = param(1, 'BLAS threads (small matrices: 1 gives the lowest latency; 0 '
                              'leaves the default)', min=0, max=256)

    def __post_init__(self) -> None:
        if self.label_tmax <= self.label_tmin:
            msg = (f"'label_tmax' ({self.label_tmax} s) must be after 'label_tmin' "
                   f'({self.label_tmin} s).')
            raise ClassifierError(msg)
