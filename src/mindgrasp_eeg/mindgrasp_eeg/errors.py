"""The EEG package's one exception class (re-exported as ``mindgrasp_eeg.EEGError``)."""

__all__ = ['EEGError']


class EEGError(Exception):
    """Any problem of the EEG package; the message names the problem and the fix."""
