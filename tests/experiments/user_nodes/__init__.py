"""A user's own nodes, as a researcher would write them, for the --launch tests."""
