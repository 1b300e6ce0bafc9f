"""``mindgrasp evaluate decoding``: per-subject decoding of real EEGMMIDB runs in MOABB's terms
(mindgrasp_experiments.decoding), on a small, fast setting."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mindgrasp_classifier.evaluation import RESULT_COLUMNS
from mindgrasp_experiments import decoding

SHARED_DATA = Path(__file__).resolve().parents[3] / 'shared' / 'data'


@pytest.fixture(scope='module')
def eegbci_path() -> str:
    path = os.environ.get('MNE_DATASETS_EEGBCI_PATH') or str(SHARED_DATA)
    if not (Path(path) / 'MNE-eegbci-data').is_dir():
        pytest.skip(f'EEGMMIDB data not found at {path}; set MNE_DATASETS_EEGBCI_PATH.')
    os.environ['MNE_DATASETS_EEGBCI_PATH'] = path
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'evaluate', 'decoding',
                           *args], capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_two_subjects_give_a_moabb_table(tmp_path: Path, eegbci_path: str) -> None:
    out = tmp_path / 'decoding'
    proc = run_cli('--subjects', '1,7', '--tasks', 'hands_feet,left_right,rest_imagery',
                   '--pipelines', 'TS+LR,MG MDM', '--evaluations', 'LeaveOneRunOut',
                   '--runs', '4,6,8', '--out', str(out))
    assert proc.returncode == 0, proc.stderr
    with (out / 'results.csv').open() as f:
        reader = csv.DictReader(f)
        rows = list(reader)
    assert reader.fieldnames[:10] == list(RESULT_COLUMNS)
    assert len(rows) == 2 * 3 * 2
    assert {r['dataset'] for r in rows} == {'PhysionetMotorImagery'}
    by = {(int(r['subject']), r['task'], r['pipeline']): r for r in rows}
    # S001: runs 4, 6, 8 here; hands/feet is in run 6 only, so leave-run-out cannot score it
    assert by[(1, 'hands_feet', 'MG MDM')]['score'] == 'nan'
    assert by[(1, 'hands_feet', 'MG MDM')]['n_folds'] == '0'
    for subject in (1, 7):
        for pipe in ('TS+LR', 'MG MDM'):
            row = by[(subject, 'rest_imagery', pipe)]
            assert row['metric'] == 'roc_auc' and int(row['n_folds']) == 3
            assert float(row['score']) > 0.6, row          # chance 0.5
        assert int(by[(subject, 'left_right', 'TS+LR')]['n_folds']) == 2    # runs 4 and 8
    assert by[(1, 'left_right', 'TS+LR')]['channels'] == '64'
    assert int(by[(1, 'left_right', 'MG MDM')]['channels']) < 64
    table = (out / 'table.md').read_text()
    assert '#### LeaveOneRunOut: rest vs any imagery (roc_auc)' in table
    assert '| S001 |' in table and '| S007 |' in table and '| **median** |' in table
    assert (out / 'decoding.png').stat().st_size > 10_000


@pytest.mark.parametrize(('args', 'message'), [
    (['--subjects', '0-3'], "'0-3': EEGMMIDB has subjects 1-109"),
    (['--subjects', '1', '--pipelines', 'EEGNet'], 'unknown pipeline EEGNet; choose from MDM'),
    (['--subjects', '1', '--tasks', 'up_down'], 'unknown task up_down'),
    (['--subjects', '5'], 'EEGMMIDB subject 5 has none of the imagery runs'),
])
def test_bad_arguments_are_one_line(tmp_path: Path, eegbci_path: str, args: list[str],
                                    message: str) -> None:
    proc = run_cli(*args, '--out', str(tmp_path / 'x'))
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('mindgrasp evaluate decoding: '), proc.stderr
    assert message in lines[0]
    assert not (tmp_path / 'x' / 'results.csv').exists()


def test_subject_ranges_parse() -> None:
    assert decoding.parse_subjects('1-4,6-12') == [1, 2, 3, 4, *range(6, 13)]
    assert decoding.parse_subjects('3,1,3') == [3, 1]
