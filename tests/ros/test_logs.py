"""A logging call site keeps one severity, as in rclpy (``Logger severity cannot be changed
between calls``), and ``log_at`` logs at a level chosen at run time without tripping it."""

from __future__ import annotations

import pytest

from mindgrasp_ros.logs import log_at
from mindgrasp_ros.runtime.logging import RcutilsLogger


def test_one_call_site_one_severity_as_rclpy() -> None:
    logger = RcutilsLogger('logs_test')
    # as in rclpy, a call site takes its severity only when that severity is enabled: the
    # level is set here, not left to whatever default an earlier test in this process set
    logger.set_level('info')

    def say(warn: bool) -> None:
        (logger.warning if warn else logger.info)('one call site')

    say(False)                                  # the site takes INFO
    say(False)
    with pytest.raises(ValueError, match='severity cannot be changed between calls'):
        say(True)
    logger.info('another line: its own site')
    logger.warning('and another')


@pytest.mark.parametrize('levels', [('info', 'warning', 'error', 'info', 'debug', 'fatal')])
def test_log_at_any_level_from_one_line(levels, capsys) -> None:
    logger = RcutilsLogger('logs_test_at')
    logger.set_level('debug')
    for level in levels:
        log_at(logger, level, f'at {level}')
    err = capsys.readouterr().err
    assert '[WARN]' in err and '[ERROR]' in err and '[FATAL]' in err
    with pytest.raises(ValueError, match="unknown level 'loud'"):
        log_at(logger, 'loud', 'x')
