"""Verbs of the mindgrasp command (entry points 'mindgrasp.verb'), one module each."""
