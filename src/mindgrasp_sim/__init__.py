"""mindgrasp_sim."""
