"""Every command validates its numbers: one line naming the option and the value, exit 2, no
traceback (``experiment random-locations --seed -1`` used to end in numpy's traceback)."""

from __future__ import annotations

import argparse

import pytest

from mindgrasp_cli.cli import main as cli_main
from mindgrasp_common.cli_checks import (
    non_negative_float,
    non_negative_int,
    positive_float,
    positive_int,
    probability,
)


@pytest.mark.parametrize(('argv', 'message'), [
    (['experiment', 'random-locations', '--seed', '-1'], 'argument --seed: must be >= 0, got -1'),
    (['experiment', 'random-locations', '--trials', 'x'],
     "argument --trials: 'x' is not a whole number"),
    (['experiment', 'random-locations', '--trial-timeout', 'nan'],
     "argument --trial-timeout: 'nan' is not a finite number"),
    (['experiment', 'set-locations', '--accuracy', '1.5'],
     'argument --accuracy: must be between 0 and 1, got 1.5'),
    (['eeg', 'virtual-amp', '--accuracy', '1.5'],
     'argument --accuracy: must be between 0 and 1, got 1.5'),
    (['eeg', 'virtual-amp', '--seed', '-3'], 'argument --seed: must be >= 0, got -3'),
    (['trainer', 'schedule', '--n-trials', '0'], 'argument --n-trials: must be >= 1, got 0'),
    (['train', 'vision', '--epochs', '-1'], 'argument --epochs: must be >= 1, got -1'),
    (['train', 'classifier', '--window', '0'], 'argument --window: must be > 0, got 0'),
    (['bag', 'play', 'x', '--rate', '-2'], 'argument -r/--rate: must be > 0, got -2'),
    (['topic', 'hz', '/x', '--window', '0'], 'argument -w/--window: must be >= 1, got 0'),
    (['launch', 'sim', '--sigint-timeout', '-1'],
     'argument --sigint-timeout: must be > 0, got -1'),
])
def test_bad_numbers_exit_2_with_one_line(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        cli_main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert message in err, err
    assert 'Traceback' not in err


@pytest.mark.parametrize(('check', 'good', 'bad'), [
    (non_negative_int, ('0', '7'), ('-1', '1.5', 'x')),
    (positive_int, ('1', '90'), ('0', '-2', 'nan')),
    (non_negative_float, ('0', '2.5'), ('-0.1', 'inf', 'x')),
    (positive_float, ('0.5', '30'), ('0', '-1', 'nan')),
    (probability, ('0', '0.9', '1'), ('-0.1', '1.01', 'x')),
])
def test_checkers(check, good, bad):
    for text in good:
        assert check(text) == float(text)
    for text in bad:
        with pytest.raises(argparse.ArgumentTypeError):
            check(text)
