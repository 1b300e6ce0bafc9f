"""Fixtures of the classifier tests."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[3] / 'shared' / 'data'


@pytest.fixture(scope='session')
def eegbci_path() -> str:
    """Folder with EEGMMIDB S001 for MNE's loader; skips when it is not available."""
    path = os.environ.get('MNE_DATASETS_EEGBCI_PATH') or str(SHARED_DATA)
    if not (Path(path) / 'MNE-eegbci-data').is_dir():
        pytest.skip(f'EEGMMIDB data not found at {path}; set MNE_DATASETS_EEGBCI_PATH.')
    os.environ['MNE_DATASETS_EEGBCI_PATH'] = path
    return path
