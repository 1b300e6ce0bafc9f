"""PyBullet plumbing of the simulation: a client that binds its functions once, and a guard that
keeps PyBullet's C output off the caller's stdout."""

from __future__ import annotations

import contextlib
import ctypes
import functools
import os
import sys
from collections.abc import Iterator

from mindgrasp_sim.pybullet_quiet import BulletClient, pb


class _Client(BulletClient):
    """BulletClient that binds each pybullet function to its client once: the stock one builds a
    new ``functools.partial`` (after an ``inspect`` check) on every call, thousands per simulated
    second in the physics loop."""

    def __init__(self, connection_mode: int) -> None:
        # BulletClient connects with options='', and pybullet's C code prints "argv[0]=" for any
        # options string: two lines per Simulation, per trial in an experiment. pb.connect
        # without options prints nothing. (The attributes are the ones BulletClient sets.)
        self._shapes: dict = {}
        self._pid = os.getpid()
        self._client = pb.connect(connection_mode)

    def __getattr__(self, name: str) -> object:
        attribute = super().__getattr__(name)
        if name != 'disconnect' and isinstance(attribute, functools.partial):
            self.__dict__[name] = attribute
        return attribute


@contextlib.contextmanager
def _c_stdout_to_stderr() -> Iterator[None]:
    """PyBullet's C code may print to stdout while it connects (the GUI's OpenGL report) or loads
    a URDF (its importer's warnings); send it to stderr so stdout stays the caller's (e.g. a
    command's --json line)."""
    libc = ctypes.CDLL(None)
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        libc.fflush(None)                # C stdio buffers go out while fd 1 is still stderr
        os.dup2(saved, 1)
        os.close(saved)


