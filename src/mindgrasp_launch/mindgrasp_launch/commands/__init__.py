"""The launcher's own command: ``mindgrasp launch`` (registered in this package's setup.py)."""
