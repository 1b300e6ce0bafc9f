"""The one exception class of the launcher."""

from __future__ import annotations


class LaunchError(Exception):
    """A launch description, argument or run directory problem, stated with its fix."""
