"""One line for every bad input of issue 42 (not the bag ones): a model whose arrays hold NaN
(checksum recomputed) or that names its arrays file with a path, ``--out`` in a missing folder,
a parameter-file key with a typo, and a table of hostile paths to the commands that read
files or runs. Each ends with one stderr line naming the problem, a non-zero exit code and no
traceback."""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from mindgrasp_cli import cli
from mindgrasp_common.resources import resolve_path

DEFAULT_MODEL = 'package://mindgrasp_classifier/models/default_classifier.json'


def _run(argv: list[str]) -> int | None:
    try:
        return cli.main(argv)
    except SystemExit as exc:
        return exc.code


def _one_line(capsys: pytest.CaptureFixture, code: int | None) -> str:
    err = capsys.readouterr().err
    assert 'Traceback' not in err, err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert code not in (0, None), err
    return lines[0]


@pytest.fixture
def model_copy(tmp_path: Path) -> Path:
    """The shipped model's .json and .npz, copied (the checksum still matches)."""
    src = resolve_path(DEFAULT_MODEL, 'mindgrasp_classifier')
    for suffix in ('.json', '.npz'):
        shutil.copy(src.with_suffix(suffix), tmp_path / src.with_suffix(suffix).name)
    return tmp_path / src.name


def _rewrite_arrays(json_path: Path, change) -> None:
    """Change the arrays, then recompute the checksum in the .json (a damaged model that still
    passes the checksum: the file was written damaged)."""
    npz = json_path.with_suffix('.npz')
    with np.load(npz) as z:
        arrays = {k: z[k].copy() for k in z.files}
    change(arrays)
    with open(npz, 'wb') as f:
        np.savez(f, **arrays)
    meta = json.loads(json_path.read_text())
    meta['arrays_sha256'] = hashlib.sha256(npz.read_bytes()).hexdigest()
    json_path.write_text(json.dumps(meta))


def test_a_model_whose_arrays_hold_nan_is_one_line(model_copy, capsys) -> None:
    def poison(arrays: dict) -> None:
        key = next(k for k in arrays if k.startswith('clf_'))
        arrays[key][..., 0, 0] = np.nan

    _rewrite_arrays(model_copy, poison)
    line = _one_line(capsys, _run(['evaluate', 'classifier', '--model', str(model_copy),
                                   '--eegbci', '1']))
    assert 'holds non-finite numbers (NaN or inf)' in line and 'retrain' in line, line


def test_a_model_whose_matrices_are_not_covariances_is_one_line(model_copy, capsys) -> None:
    def flip(arrays: dict) -> None:
        arrays['reference'] = -arrays['reference']       # negative definite

    _rewrite_arrays(model_copy, flip)
    line = _one_line(capsys, _run(['evaluate', 'classifier', '--model', str(model_copy),
                                   '--eegbci', '1']))
    assert 'not symmetric positive definite' in line, line


@pytest.mark.parametrize('name', ['../x.npz', '/etc/passwd', 'sub/m.npz', '..', '.'])
def test_an_arrays_file_outside_the_model_folder_is_one_line(model_copy, name, capsys):
    meta = json.loads(model_copy.read_text())
    meta['arrays_file'] = name
    model_copy.write_text(json.dumps(meta))
    line = _one_line(capsys, _run(['evaluate', 'classifier', '--model', str(model_copy),
                                   '--eegbci', '1']))
    assert 'is not a file name beside the .json' in line, line


def test_out_in_a_missing_folder_creates_nothing_and_names_out(tmp_path, capsys) -> None:
    out = tmp_path / 'missing' / 'x'
    line = _one_line(capsys, _run(['experiment', 'set-locations', '--trials', '1',
                                   '--subject', 'oracle', '--out', str(out)]))
    assert line.count('--out') >= 1 and '--run-dir' not in line, line
    assert 'does not exist' in line, line
    assert not (tmp_path / 'missing').exists()


def test_a_parameter_file_key_with_a_typo_is_refused(tmp_path) -> None:
    """rclpy keeps an undeclared override unused: the typo ran on the default silently."""
    params = tmp_path / 'fsm.yaml'
    params.write_text(yaml.safe_dump({'fsm': {'ros__parameters': {'lock_durtion': 2.0}}}))
    done = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'run', 'mindgrasp_fsm',
                           'fsm_node', '--ros-args', '--params-file', str(params), '-p',
                           'graph_check_wait:=0.0'], capture_output=True, text=True,
                          timeout=120, check=False)
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert done.returncode == 2, done.stderr
    assert len(lines) == 1 and 'Traceback' not in done.stderr, done.stderr
    assert "Parameter 'lock_durtion' is not declared by node 'fsm'" in lines[0], lines[0]
    assert "did you mean 'lock_duration'" in lines[0], lines[0]


# -- hostile paths -------------------------------------------------------------------------------

def _hostile_paths(folder: Path) -> list[str]:
    folder.mkdir(exist_ok=True)
    (folder / 'empty.json').write_text('')
    (folder / 'garbage.mcap').write_bytes(np.random.default_rng(0).bytes(4096))
    (folder / 'a_folder').mkdir(exist_ok=True)
    return [str(folder / 'missing' / 'x'), '../no_such_thing', str(folder / 'a_folder'),
            str(folder / 'empty.json'), str(folder / 'garbage.mcap'), 'bad\x00name',
            'x' * 5000, '']


#: commands that read a file or a run; {p} is the hostile path, {d} a writable folder
READERS = [
    ['replay', '{p}'],
    ['export', 'eeg', '{p}'],
    ['experiment', 'report', '{p}'],
    ['eeg', 'play', '{p}'],
    ['evaluate', 'classifier', '--model', '{p}', '--eegbci', '1'],
    ['train', 'classifier', '--bag', '{p}', '--out', '{d}/model'],
    ['experiment', 'set-locations', '--trials', '1', '--subject', '{p}', '--out', '{d}/run'],
    ['experiment', 'random-locations', '--trials', '1', '--realism', '{p}', '--out',
     '{d}/run'],
    ['experiment', 'set-locations', '--trials', '1', '--launch', '{p}', '--out', '{d}/run'],
    ['session', 'run', '--subject', 's1', '--plan', '{p}', '--root', '{d}'],
]


@pytest.mark.parametrize('argv', READERS, ids=lambda a: ' '.join(a[:3]))
def test_hostile_paths_are_one_line(argv, tmp_path, capsys) -> None:
    for k, path in enumerate(_hostile_paths(tmp_path / 'inputs')):
        if not path and '--realism' in argv:
            continue             # an empty --realism is a valid value: none
        work = tmp_path / f'work{k}'
        work.mkdir()
        words = [w.format(p=path, d=work) for w in argv]
        code = _run(words)
        err = capsys.readouterr().err
        lines = [line for line in err.splitlines() if line.strip()]
        assert 'Traceback' not in err and len(lines) == 1, (path[:80], err[-2000:])
        assert code not in (0, None), (path[:80], err)
