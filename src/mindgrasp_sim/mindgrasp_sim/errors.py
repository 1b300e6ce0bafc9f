"""The one exception class of mindgrasp_sim."""


class SimError(ValueError):
    """Bad input to the simulation (scene file, parameter, command): the message says the fix."""
