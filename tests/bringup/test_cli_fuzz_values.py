"""A fuzz of the CLI's numbers and paths finds no traceback (issue 42).

Numbers: every number option of every verb (found in the CLI's own table, so verbs added later
are covered) must have bounds, and takes hostile text (``99999999999999999999``, ``1e400``,
``nan``, ``0x10``, Arabic digits, blanks ...) plus a seeded random draw of number-like text:
argparse either refuses it in one line with exit code 2, or the value it returns is finite and
within the option's bounds (no ``--trials 99999999999999999999`` reaching numpy's
OverflowError). In-process, before any DDS traffic.

Paths: the commands that read a file or a run take hostile paths (missing, ``..``-relative, a
folder for a file, an empty file, random bytes, a NUL byte, 5000 characters): one line, exit code
non-zero, no traceback. ``--out`` creates only the run folder itself and names ``--out``.
"""

from __future__ import annotations

import argparse
import random

import pytest

from mindgrasp_cli import cli
from mindgrasp_common import cli_checks
from mindgrasp_common.cli_checks import MAX_FLOAT, MAX_INT

#: number checkers and the range each accepts (lower, upper)
CHECKERS = {
    cli_checks.non_negative_int: (0, MAX_INT), cli_checks.positive_int: (1, MAX_INT),
    cli_checks.non_negative_float: (0.0, MAX_FLOAT),
    cli_checks.positive_float: (0.0, MAX_FLOAT), cli_checks.probability: (0.0, 1.0),
    cli_checks.finite_float: (-MAX_FLOAT, MAX_FLOAT),
}

HOSTILE_NUMBERS = ['99999999999999999999', '-99999999999999999999', '2147483648', '1e400',
                   '-1e400', 'nan', 'NaN', 'inf', '-inf', '1e308', '-1e308', '0x10', '', ' ',
                   '\u0663', '1_000', '3.5', '-0', '+7', '1e9', '1e10', '--', '1e-400', '0.0',
                   '9' * 400, '1' + '0' * 30 + '.5', '-2147483649']


def _verbs() -> list[tuple[str, ...]]:
    return [(command,) if isinstance(target, str) else (command, verb)
            for command, target in cli.commands().items()
            for verb in ([None] if isinstance(target, str) else target)]


def _parser(prefix: tuple[str, ...]) -> argparse.ArgumentParser:
    parser: argparse.ArgumentParser = cli.build_parser(list(prefix))
    for word in prefix:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[word]
    return parser


def _is_number_type(kind: object) -> bool:
    return kind in (int, float) or kind in CHECKERS or hasattr(kind, 'bounds')


def _number_options() -> list:
    cases = []
    for prefix in _verbs():
        for action in _parser(prefix)._actions:
            if action.option_strings and _is_number_type(action.type):
                cases.append(pytest.param(prefix, action.option_strings[-1], action.type,
                                          id=f"{' '.join(prefix)} {action.option_strings[-1]}"))
    return cases


NUMBER_OPTIONS = _number_options()


def _bounds(kind: object) -> tuple[float, float]:
    return getattr(kind, 'bounds', None) or CHECKERS[kind]


def test_every_number_option_has_bounds() -> None:
    """Plain ``type=int``/``float`` took ``99999999999999999999`` and ``nan``."""
    assert len(NUMBER_OPTIONS) > 40
    unbounded = [p.id for p in NUMBER_OPTIONS if p.values[2] in (int, float)]
    assert not unbounded, unbounded


def _random_numbers(rng: random.Random, n: int) -> list[str]:
    """Number-like text: signs, digits (also long runs), dots, exponents, words, blanks."""
    pieces = ['-', '+', '0', '1', '7', '9' * rng.randint(1, 40), '.', 'e', 'E', '308', '-400',
              'inf', 'nan', ' ', '_', 'x', '\u0663', '\u00bd']
    return [''.join(rng.choice(pieces) for _ in range(rng.randint(1, 6))) for _ in range(n)]


@pytest.mark.parametrize(('prefix', 'flag', 'kind'), NUMBER_OPTIONS)
def test_hostile_numbers_are_refused_in_one_line_or_in_bounds(prefix, flag, kind, capsys):
    rng = random.Random(f'{prefix} {flag}')          # seeded: the same draw every run
    low, high = _bounds(kind)
    parser = _parser(prefix)
    for text in HOSTILE_NUMBERS + _random_numbers(rng, 40):
        try:
            value = kind(text)
        except argparse.ArgumentTypeError as exc:
            assert '\n' not in str(exc) and str(exc), (flag, text)
            continue
        except (ValueError, TypeError):
            continue                 # argparse turns these into its own one-line usage error
        assert low <= value <= high, (flag, text, value)
    # the whole command line: one stderr line, exit 2 (argparse's own path, not the checker's)
    with pytest.raises(SystemExit) as exc:
        parser.parse_args([f'{flag}=99999999999999999999999'])
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert exc.value.code == 2 and len(lines) == 1, lines


def test_a_huge_trial_count_is_one_line(capsys) -> None:
    """``experiment random-locations --trials 99999999999999999999`` ended in OverflowError."""
    with pytest.raises(SystemExit) as exc:
        cli.main(['experiment', 'random-locations', '--trials', '99999999999999999999'])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and 'Traceback' not in err, err
    assert 'argument --trials: must be <= ' in err and len(err.strip().splitlines()) == 1, err
