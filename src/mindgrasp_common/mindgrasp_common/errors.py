"""The exception classes of :mod:`mindgrasp_common`."""

from __future__ import annotations

__all__ = ['CommonError', 'ResourceNotFoundError']


class CommonError(ValueError):
    """Invalid value for a shared type (the message names the value and the fix)."""


class ResourceNotFoundError(CommonError, FileNotFoundError):
    """A package, or a data file of a package, that does not exist."""
