"""mindgrasp_classifier: motor-imagery decoding with Riemannian geometry.

Layers (ROS-free unless named ``*_node``):

- :mod:`.preprocessing`: causal SOS band-pass with state across chunks, channel selection,
  sliding-window grid, vectorised OAS covariances.
- :mod:`.pipelines`: scikit-learn classifiers on covariances (MDM, FgMDM, tangent space +
  logistic regression) with per-class distances and certainty ``mean(d) - min(d)``.
- :mod:`.model`: :class:`~.model.MiModel` and its safe file format (JSON + ``.npz``, no pickle).
- :mod:`.decoder`: :class:`~.decoder.MiDecoder`, the online decoder (chunks in, predictions out,
  NaN/flat rejection, adaptive class means and re-centering), and the offline helpers that use
  the same filter and window code.
- :mod:`.data`, :mod:`.training`: labelled recordings (EDF via MNE, EEGMMIDB, rosbag2 runs),
  training with grouped cross-validation, evaluation.
- :mod:`.classifier_node`: the ROS 2 node; :mod:`.commands.train_classifier`,
  :mod:`.commands.evaluate_classifier`: the ``mindgrasp train|evaluate classifier`` commands;
  :mod:`.live`: ``evaluate --live``.
"""

from mindgrasp_classifier.errors import ClassifierError

__all__ = ['ClassifierError']
