"""`mindgrasp trainer schedule` (commands/trainer_schedule.py): the schedule the nodes will use."""

from __future__ import annotations

import argparse
import csv
import io
import json

import pytest

from mindgrasp_trainer.commands import trainer_schedule
from mindgrasp_trainer.graz import GrazProtocol
from mindgrasp_trainer.trainer import TrainerProtocol


def run(capsys, *argv: str) -> tuple[int, str, str]:
    parser = argparse.ArgumentParser()
    trainer_schedule.add_arguments(parser)
    code = trainer_schedule.main(parser.parse_args(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_graz_csv_matches_the_protocol(capsys):
    code, out, err = run(capsys, '--n-trials', '8', '--seed', '3')
    assert code == 0
    rows = list(csv.DictReader(io.StringIO(out)))
    events = GrazProtocol(n_trials=8, seed=3, start_delay=5.0).schedule()
    assert [(r['phase'], int(r['trial']), int(r['class_index'])) for r in rows] == [
        (e.phase, e.trial, e.class_index) for e in events
    ]
    assert [float(r['onset_s']) for r in rows] == pytest.approx([e.onset for e in events], abs=1e-3)
    assert '# 8 trials (both_feet 2, both_hands 2, left_hand 2, right_hand 2)' in err


def test_trainer_json_matches_the_protocol(capsys):
    code, out, _ = run(capsys, '--paradigm', 'trainer', '--n-trials', '6', '--seed', '1',
                       '--classes', '0', '1', '--json')  # fmt: skip
    assert code == 0
    data = json.loads(out)
    moves = [e for e in data['events'] if e['phase'] == 'move']
    order = TrainerProtocol(n_trials=6, seed=1, classes=(0, 1)).order
    assert [e['class_index'] for e in moves] == order.tolist()
    assert data['class_counts'] == {'left_hand': 3, 'right_hand': 3}
    assert data['duration_s'] == pytest.approx(5.0 + 6 * 4.0)


def test_bad_arguments_exit_2_with_the_reason(capsys):
    # a class index beyond the four classes is refused while parsing (argparse's exit 2)
    with pytest.raises(SystemExit) as exited:
        run(capsys, '--classes', '0', '9')
    assert exited.value.code == 2
    assert 'argument --classes: must be <= 3, got 9' in capsys.readouterr().err
