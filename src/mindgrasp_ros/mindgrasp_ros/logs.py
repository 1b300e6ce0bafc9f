"""Logging at a level chosen at run time, in a way rclpy accepts.

rclpy ties each logging call site to the severity of its first message: the same line logging
at another severity raises ``ValueError('Logger severity cannot be changed between calls.')``
(``rclpy/impl/rcutils_logger.py``, ``RcutilsLogger.log``), so ``(logger.info if ok else
logger.warning)(text)`` works once and then kills the node. :func:`log_at` gives each level a
call site of its own.
"""

from __future__ import annotations

__all__ = ['LEVELS', 'log_at']

#: level names :func:`log_at` takes
LEVELS = ('debug', 'info', 'warning', 'error', 'fatal')


def log_at(logger: object, level: str, message: str) -> None:
    """Log ``message`` with ``logger`` (a node's ``get_logger()``, ours or rclpy's) at ``level``,
    one of :data:`LEVELS`."""
    if level == 'debug':
        logger.debug(message)
    elif level == 'info':
        logger.info(message)
    elif level == 'warning':
        logger.warning(message)
    elif level == 'error':
        logger.error(message)
    elif level == 'fatal':
        logger.fatal(message)
    else:
        msg = f'log_at: unknown level {level!r}; use one of {", ".join(LEVELS)}.'
        raise ValueError(msg)
