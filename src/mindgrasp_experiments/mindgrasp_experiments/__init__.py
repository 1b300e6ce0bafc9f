"""mindgrasp_experiments: the paper's grasp protocols run through the node graph.

Layers:

- :mod:`~mindgrasp_experiments.protocols`: what each trial asks for, from (seed, trial) alone.
- :mod:`~mindgrasp_experiments.records`: the one trial record and success definition
  (``TrialRecord``, ``TrialTracker``), CSV and Parquet.
- :mod:`~mindgrasp_experiments.summary`: rates with Wilson 95 % intervals, the paper's figures.
- :mod:`~mindgrasp_experiments.trial_manager_node`: the node that runs trials, live and in
  lock-step.
- :mod:`~mindgrasp_experiments.subjects`: noise, virtual and oracle subjects (launch arguments,
  the noise-trained classifier, the oracle node).
- :mod:`~mindgrasp_experiments.engine`: a launch profile composed in one process on simulated
  time (``mindgrasp_ros.graph.lockstep.LockstepRunner``), one trial per composed graph.
- :mod:`~mindgrasp_experiments.workers`: trials spread over worker processes.
- :mod:`~mindgrasp_experiments.report`, :mod:`~mindgrasp_experiments.plots`: summary.json,
  report.md, PNG and SVG plots.
"""


class ExperimentError(Exception):
    """Bad experiment input or a run that cannot go on; the message names the fix."""


__all__ = ['ExperimentError']
