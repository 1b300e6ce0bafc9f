"""Tests of mindgrasp_vision."""
