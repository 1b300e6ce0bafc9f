"""mindgrasp_eeg."""
