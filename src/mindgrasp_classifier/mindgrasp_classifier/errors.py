"""The one exception class of :mod:`mindgrasp_classifier`."""

from __future__ import annotations


class ClassifierError(ValueError):
    """Bad input, model or data for the MI classifier; the message names the problem and the fix."""
