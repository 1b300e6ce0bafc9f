"""mindgrasp_trainer."""
