"""mindgrasp_classifier."""
