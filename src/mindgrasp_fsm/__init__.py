"""mindgrasp_fsm."""
