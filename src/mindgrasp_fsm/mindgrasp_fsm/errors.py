"""The one exception class of :mod:`mindgrasp_fsm`."""

from __future__ import annotations


class FsmError(ValueError):
    """Bad input or configuration of the grasp controller; the message names the problem and fix."""
