"""``rclpy.logging``: named loggers with severities, printed to stderr and sent to /rosout."""

from __future__ import annotations

import enum
import inspect
import os
import sys
import threading
import time
from collections.abc import Callable

__all__ = ['LoggingSeverity', 'RcutilsLogger', 'get_logger', 'set_logger_level']


class LoggingSeverity(enum.IntEnum):
    UNSET = 0
    DEBUG = 10
    INFO = 20
    WARN = 30
    ERROR = 40
    FATAL = 50


_levels: dict[str, LoggingSeverity] = {}
_default_level = LoggingSeverity.INFO
_lock = threading.Lock()
#: Called for every emitted record: (severity, logger name, message, file, function, line).
_sinks: list[Callable[[LoggingSeverity, str, str, str, str, int], None]] = []


def add_sink(sink: Callable[[LoggingSeverity, str, str, str, str, int], None]) -> None:
    """Call ``sink(severity, name, message, file, function, line)`` for every emitted record
    (a node's ``/rosout`` publisher)."""
    _sinks.append(sink)


def remove_sink(sink: Callable[[LoggingSeverity, str, str, str, str, int], None]) -> None:
    """Stop calling ``sink`` (nothing happens when it was not added)."""
    if sink in _sinks:
        _sinks.remove(sink)


def parse_severity(level: str | int) -> LoggingSeverity:
    if isinstance(level, int):
        return LoggingSeverity(level)
    try:
        return LoggingSeverity[level.strip().upper().replace('WARNING', 'WARN')]
    except KeyError:
        valid = ', '.join(s.name.lower() for s in LoggingSeverity if s)
        msg = f'Unknown log level {level!r}; use one of {valid}.'
        raise ValueError(msg) from None


def set_logger_level(name: str, level: LoggingSeverity | str | int) -> None:
    global _default_level
    sev = parse_severity(level)
    with _lock:
        if name == '':
            _default_level = sev
        else:
            _levels[name] = sev


def get_logger_effective_level(name: str) -> LoggingSeverity:
    parts = name.split('.')
    while parts:
        level = _levels.get('.'.join(parts))
        if level:
            return level
        parts.pop()
    return _default_level


def _stderr_sink(sev: LoggingSeverity, name: str, message: str, *_: object) -> None:
    stamp = time.time()
    line = f'[{sev.name}] [{stamp:.9f}] [{name}]: {message}\n'
    try:
        (sys.stderr if sev >= LoggingSeverity.WARN or _to_stderr else sys.stdout).write(line)
        (sys.stderr if sev >= LoggingSeverity.WARN or _to_stderr else sys.stdout).flush()
    except (ValueError, OSError):  # stream closed at interpreter exit
        pass


_to_stderr = os.environ.get('RCUTILS_LOGGING_USE_STDOUT', '1') == '0'


class RcutilsLogger:
    """A named logger with rclpy's methods (``info``, ``warning``, ``once``, ``throttle``...).

    As rclpy's, a call site (function, file, line, bytecode offset) keeps the severity of its
    first message: logging at another severity from the same call raises ``ValueError('Logger
    severity cannot be changed between calls.')`` (``mindgrasp_ros.logs.log_at`` logs at a level
    chosen at run time).
    """

    def __init__(self, name: str = '') -> None:
        self.name = name
        self._once: set[tuple[str, int]] = set()
        self._last: dict[tuple[str, int], float] = {}
        self._severities: dict[tuple[str, str, int, int], LoggingSeverity] = {}

    def get_child(self, name: str) -> RcutilsLogger:
        return RcutilsLogger(f'{self.name}.{name}' if self.name else name)

    def set_level(self, level: LoggingSeverity | str | int) -> None:
        set_logger_level(self.name, level)

    def get_effective_level(self) -> LoggingSeverity:
        return get_logger_effective_level(self.name)

    def is_enabled_for(self, severity: LoggingSeverity) -> bool:
        return severity >= self.get_effective_level()

    def log(self, message: object, severity: LoggingSeverity, *, once: bool = False,
            throttle_duration_sec: float | None = None, skip_first: bool = False,
            **_kwargs: object) -> bool:
        if not self.is_enabled_for(severity):
            return False
        caller = inspect.currentframe()
        while caller is not None and caller.f_code.co_filename == __file__:
            caller = caller.f_back            # the first frame outside this module, as rclpy's
        key = (caller.f_code.co_filename, caller.f_lineno) if caller else ('', 0)
        site = (*key, caller.f_code.co_name, caller.f_lasti) if caller else ('', 0, '', 0)
        if self._severities.setdefault(site, severity) != severity:
            msg = 'Logger severity cannot be changed between calls.'
            raise ValueError(msg)
        if once:
            if key in self._once:
                return False
            self._once.add(key)
        if throttle_duration_sec:
            now = time.monotonic()
            last = self._last.get(key)
            if last is None and skip_first:
                self._last[key] = now
                return False
            if last is not None and now - last < throttle_duration_sec:
                return False
            self._last[key] = now
        text = str(message)
        file, func, line = (caller.f_code.co_filename, caller.f_code.co_name,
                            caller.f_lineno) if caller else ('', '', 0)
        _stderr_sink(severity, self.name, text)
        for sink in list(_sinks):
            try:
                sink(severity, self.name, text, file, func, line)
            except Exception:
                pass
        return True

    def debug(self, message: object, **kw: object) -> bool:
        return self.log(message, LoggingSeverity.DEBUG, **kw)

    def info(self, message: object, **kw: object) -> bool:
        return self.log(message, LoggingSeverity.INFO, **kw)

    def warning(self, message: object, **kw: object) -> bool:
        return self.log(message, LoggingSeverity.WARN, **kw)

    warn = warning

    def error(self, message: object, **kw: object) -> bool:
        return self.log(message, LoggingSeverity.ERROR, **kw)

    def fatal(self, message: object, **kw: object) -> bool:
        return self.log(message, LoggingSeverity.FATAL, **kw)


def get_logger(name: str) -> RcutilsLogger:
    return RcutilsLogger(name)
