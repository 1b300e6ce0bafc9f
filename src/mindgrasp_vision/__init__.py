"""mindgrasp_vision."""
