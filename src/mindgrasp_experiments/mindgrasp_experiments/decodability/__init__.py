"""How decodable a subject's motor imagery is: the same figures for real and virtual subjects.

A subject's *decodability figures* are offline accuracies of classifiers calibrated on one set of
recordings and tested on another (another run or session), for five questions: the tasks of
:data:`mindgrasp_classifier.evaluation.TASKS` (four classes, left vs right hand, both hands vs
both feet, rest vs any imagery, rest vs both hands).

The package is built as the field builds such measurements (MOABB: paradigm, evaluation,
pipelines):

- :mod:`.paradigm`: each recording band-passed (8-30 Hz, causal 4th-order Butterworth, as the
  online decoder), one epoch per cue (0.5-2.5 s after it), an OAS covariance per epoch, the
  covariances of a recording re-centred on their Riemannian mean (unsupervised, per recording:
  what makes calibration and test runs comparable); rest epochs carry the label
  ``mindgrasp_common.mi.REST`` (4), the decoder's rest class;
- :mod:`.figures`: the evaluation, :func:`mindgrasp_classifier.evaluation.fit_predict`
  (calibrate on one set, test on the other) with the pipelines of
  :mod:`mindgrasp_classifier.pipelines`, MDM and tangent space + logistic regression
  (``ts_lr``, classes weighted equally), both log-Euclidean. A figure is a balanced accuracy
  (mean recall over its classes: rest epochs outnumber each imagery class, and guessing "rest"
  must not score), and its score the mean of the two classifiers. These are per-trial figures
  (one 2-s epoch per cue), not the online decoder's sliding-window figures of
  :mod:`mindgrasp_classifier.training`; both subjects are measured alike, which is what
  matters here;
- :mod:`.synthetic`: the virtual subject (:func:`synthetic_figures`):
  :class:`~mindgrasp_eeg.synthetic.SyntheticEEG` runs that follow the cue schedules of a
  template (the replay subject's recordings, so both are measured on the same protocol, or
  :func:`eegmmidb_like_schedules`), one generator and one seed per run so ``nonstationarity``
  changes the conditions between runs; averaged over a few repetitions with other seeds;
- :mod:`.fit`: :func:`fit_virtual` searches the virtual subject's ``separability``,
  ``lateral_separability``, ``rest_separability`` and ``nonstationarity`` so that its figures
  match a real subject's (``mindgrasp eeg fit-virtual``). A real subject's figures rest on few
  trials (EEGMMIDB: 7-8 per class and run), so each has a sampling error of 5-12 points
  (:meth:`Decodability.standard_error`): a fit closer than that is fitting chance.

A replay subject (:func:`replay_figures`) is measured on its calibration and play recordings
(:mod:`~mindgrasp_eeg.subject_file`), labelled by their event maps. ROS-free.

    >>> cal, test = eegmmidb_like_schedules(seed=0)                    # doctest: +SKIP
    >>> synthetic_figures(cal, test, separability=0.5).scores()         # doctest: +SKIP
"""

from __future__ import annotations

from mindgrasp_common.mi import REST
from mindgrasp_experiments.decodability.figures import (
    FIGURES,
    Decodability,
    Figure,
    average,
    make_pipeline,
    measure,
    replay_figures,
    replay_recordings,
)
from mindgrasp_experiments.decodability.fit import (
    FitResult,
    default_jobs,
    fit_virtual,
    score_errors,
)
from mindgrasp_experiments.decodability.paradigm import (
    MAX_IMAGERY_S,
    PIPELINES,
    MeasureConfig,
    RunSchedule,
    common_channels,
    eegmmidb_like_schedules,
    epoch_covariances,
    labelled,
)
from mindgrasp_experiments.decodability.synthetic import (
    DEFAULT_SETTINGS,
    FIT_START,
    PARAMETER_BOUNDS,
    synthetic_figures,
    synthetic_runs,
)

__all__ = ['DEFAULT_SETTINGS', 'FIGURES', 'FIT_START', 'MAX_IMAGERY_S', 'PARAMETER_BOUNDS',
           'PIPELINES', 'REST', 'Decodability', 'Figure', 'FitResult', 'MeasureConfig',
           'RunSchedule', 'average', 'common_channels', 'default_jobs',
           'eegmmidb_like_schedules', 'epoch_covariances', 'fit_virtual', 'labelled',
           'make_pipeline', 'measure', 'replay_figures', 'replay_recordings', 'score_errors',
           'synthetic_figures', 'synthetic_runs']
