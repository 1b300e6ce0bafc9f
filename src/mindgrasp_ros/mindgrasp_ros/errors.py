"""Exceptions of the ROS 2 client layer."""


class RosError(Exception):
    """Base class of every error raised by :mod:`mindgrasp_ros`."""


class CompositionError(RosError):
    """A component could not be loaded or constructed, or a composed graph did not settle."""


class NodeCallbackError(CompositionError):
    """A callback of a composed node raised; ``node`` names it, ``error`` is the exception."""

    def __init__(self, node: str, error: BaseException) -> None:
        self.node, self.error = node, error
        super().__init__(f'node {node!r} raised {type(error).__name__}: {error}')
