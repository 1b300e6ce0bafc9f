"""mindgrasp_eeg: EEG acquisition over LSL, a virtual amplifier with a virtual subject, a dataset
player and an exporter.

Layers (ROS-free unless the module name ends in ``_node``):

- :mod:`~mindgrasp_eeg.montage`: the 32-channel g.Nautilus-like 10-20 montage and MI class names.
- :mod:`~mindgrasp_eeg.synthetic`: synthetic EEG (1/f background, alpha/mu/beta rhythms, artefacts,
  motor-imagery ERD mixed through a fixed head model), in volts.
- :mod:`~mindgrasp_eeg.subject`: the virtual subject (modes ``noise``, ``follow``, ``pursue``).
- :mod:`~mindgrasp_eeg.lsl`: LSL outlet (virtual amplifier) and inlet (acquisition) wrappers.
- :mod:`~mindgrasp_eeg.quality`: NaN/flat/railed detection, drop and out-of-order counting.
- :mod:`~mindgrasp_eeg.acquisition`: the acquisition core used by the acquisition node.
- :mod:`~mindgrasp_eeg.virtual_amp`: synthetic generator + subject + outlet, paced by a clock.
- :mod:`~mindgrasp_eeg.player`: streams EDF/GDF/BDF/FIF/XDF files over LSL with a marker stream.
- :mod:`~mindgrasp_eeg.subject_file`: replay subjects (``eegmmidb:<n>`` or a YAML subject file):
  calibration and play recordings with their event maps.
- :mod:`~mindgrasp_eeg.replay_eeg`: the replay subject's generator (real epochs by intent).
- :mod:`~mindgrasp_eeg.export`: rosbag2 (``/eeg/raw``, prompts, targets) -> FIF/EDF;
  :mod:`~mindgrasp_eeg.bids`: runs and sessions -> EEG-BIDS (mne-bids);
  :mod:`~mindgrasp_eeg.event_markers`: the events' names, shared with the LSL marker stream.
- :mod:`~mindgrasp_eeg.lsl_scope`: LSL discovery on this host unless ``MINDGRASP_LSL_SCOPE=network``
  (applied when this package is imported, before liblsl reads its configuration).
- Nodes: :mod:`~mindgrasp_eeg.acquisition_node`, :mod:`~mindgrasp_eeg.virtual_amp_node`,
  :mod:`~mindgrasp_eeg.marker_node` (events -> LSL markers).
"""

import sys

from mindgrasp_eeg.errors import EEGError

__all__ = ['EEGError']


def _apply_lsl_scope() -> None:
    from .lsl_scope import apply_lsl_scope

    try:
        apply_lsl_scope()
    except EEGError as exc:       # a bad setting keeps the safe default, and says so
        print(f'mindgrasp_eeg: {exc} Keeping LSL on this machine.', file=sys.stderr)
        apply_lsl_scope(scope='machine')


_apply_lsl_scope()
