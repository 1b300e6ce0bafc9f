"""The one exception class of :mod:`mindgrasp_bag`."""

from __future__ import annotations


class BagError(Exception):
    """A bag cannot be written, read or played; the message names the problem and the fix."""
