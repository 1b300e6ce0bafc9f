"""argparse ``type=`` checkers for numbers on the command line (ROS-free, shared by every CLI).

``parser.add_argument('--seed', type=non_negative_int)``: a bad value ends the command the way
argparse does, with one line naming the option, the value and what it must be, and exit code 2
(``--seed -1`` used to end in a traceback from numpy).

:class:`OneLineParser` is the parser of every command: a usage error (unknown flag, missing
value, bad choice) is one line on stderr, ``<prog>: error: <problem> (see <prog> --help)``, and
exit code 2, as argparse and ros2cli give it, without argparse's usage block in front.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

__all__ = ['MAX_FLOAT', 'MAX_INT', 'OneLineParser', 'bounded_float', 'bounded_int',
           'existing_directory', 'finite_float', 'non_negative_float', 'non_negative_int',
           'positive_float', 'positive_int', 'probability', 'yaml_error_text']

#: the largest whole number any option takes (a signed 32-bit int: counts, seeds, sizes): a
#: larger one (``--trials 99999999999999999999``) ended in an OverflowError deep in numpy
MAX_INT = 2**31 - 1
#: the largest magnitude any number option takes (s, Hz, m ...): 1e9 s is 31 years
MAX_FLOAT = 1e9


class OneLineParser(argparse.ArgumentParser):
    """An ``argparse.ArgumentParser`` whose usage errors are one stderr line and exit code 2.

    The usage block argparse prints first ran to 19 lines for ``train classifier`` and buried the
    one line that says what is wrong; ``--help`` still prints it in full. Sub-parsers made with
    ``add_subparsers`` inherit the class.
    """

    def error(self, message: str) -> NoReturn:
        """Print ``<prog>: error: <message> (see <prog> --help)`` and exit 2."""
        self.exit(2, f'{self.prog}: error: {message} (see {self.prog} --help)\n')


def _int(text: str, maximum: int = MAX_INT) -> int:
    try:
        value = int(text)
    except ValueError:
        msg = f'{text!r} is not a whole number'
        raise argparse.ArgumentTypeError(msg) from None
    if value > maximum:
        msg = f'must be <= {maximum}, got {text.strip()}'
        raise argparse.ArgumentTypeError(msg)
    return value


def _float(text: str, maximum: float = MAX_FLOAT) -> float:
    try:
        value = float(text)
    except ValueError:
        msg = f'{text!r} is not a number'
        raise argparse.ArgumentTypeError(msg) from None
    if not math.isfinite(value):
        msg = f'{text!r} is not a finite number'
        raise argparse.ArgumentTypeError(msg)
    if abs(value) > maximum:
        msg = f'must be between {-maximum:g} and {maximum:g}, got {text.strip()}'
        raise argparse.ArgumentTypeError(msg)
    return value


def bounded_int(minimum: int, maximum: int) -> Callable[[str], int]:
    """A checker of whole numbers from ``minimum`` to ``maximum``: ``type=bounded_int(1, 10000)``
    (``--trials``: a number of trials that could never run is refused at once)."""
    def check(text: str) -> int:
        value = _int(text, maximum)
        if value < minimum:
            msg = f'must be >= {minimum}, got {value}'
            raise argparse.ArgumentTypeError(msg)
        return value

    check.__name__ = f'bounded_int({minimum}, {maximum})'
    check.bounds = (minimum, maximum)          # type: ignore[attr-defined]
    return check


def bounded_float(minimum: float, maximum: float) -> Callable[[str], float]:
    """A checker of finite numbers from ``minimum`` to ``maximum``."""
    def check(text: str) -> float:
        value = _float(text)
        if not minimum <= value <= maximum:
            msg = f'must be between {minimum:g} and {maximum:g}, got {value:g}'
            raise argparse.ArgumentTypeError(msg)
        return value

    check.__name__ = f'bounded_float({minimum:g}, {maximum:g})'
    check.bounds = (minimum, maximum)          # type: ignore[attr-defined]
    return check


def finite_float(text: str) -> float:
    """Any finite number (times that may be negative, e.g. an epoch start before its cue);
    ``float`` alone took ``nan``, which ended in a traceback further on."""
    return _float(text)


def non_negative_int(text: str) -> int:
    """A whole number >= 0 (seeds, counts where 0 means "no limit")."""
    value = _int(text)
    if value < 0:
        msg = f'must be >= 0, got {value}'
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_int(text: str) -> int:
    """A whole number >= 1 (numbers of trials, images, epochs)."""
    value = _int(text)
    if value < 1:
        msg = f'must be >= 1, got {value}'
        raise argparse.ArgumentTypeError(msg)
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0 (durations and delays where 0 means "none" or "no limit")."""
    value = _float(text)
    if value < 0:
        msg = f'must be >= 0, got {value:g}'
        raise argparse.ArgumentTypeError(msg)
    return value


def positive_float(text: str) -> float:
    """A finite number > 0 (rates, timeouts)."""
    value = _float(text)
    if value <= 0:
        msg = f'must be > 0, got {value:g}'
        raise argparse.ArgumentTypeError(msg)
    return value


def existing_directory(text: str) -> Path:
    """A directory that exists (where a command writes files of its own names)."""
    path = Path(text)
    if not path.is_dir():
        msg = f"'{text}' is not a directory; create it first"
        raise argparse.ArgumentTypeError(msg)
    return path


def probability(text: str) -> float:
    """A number in [0, 1] (accuracies, rates of events per trial)."""
    value = _float(text)
    if not 0.0 <= value <= 1.0:
        msg = f'must be between 0 and 1, got {value:g}'
        raise argparse.ArgumentTypeError(msg)
    return value


def yaml_error_text(exc: Exception) -> str:
    """A PyYAML parse error on one line: ``line 1, column 6: expected the node content, but found
    '<stream end>'`` (its own message spans five lines with a caret drawing)."""
    mark = getattr(exc, 'problem_mark', None)
    problem = getattr(exc, 'problem', None) or ' '.join(str(exc).split())
    if mark is None:
        return problem
    return f'line {mark.line + 1}, column {mark.column + 1}: {problem}'
