"""Terminal output of the launcher: node lines prefixed by the node name, coloured on a TTY."""

from __future__ import annotations

import contextlib
import logging
import os
import sys
import threading
from pathlib import Path
from typing import TextIO

_PALETTE = ('32', '36', '33', '35', '34', '92', '96', '93', '95', '94')
_RED = '31'


def use_colour(stream: TextIO) -> bool:
    """Colour when writing to a terminal, unless ``NO_COLOR`` is set (no-color.org)."""
    if os.environ.get('NO_COLOR'):
        return False
    if os.environ.get('FORCE_COLOR'):
        return True
    try:
        return stream.isatty()
    except (AttributeError, ValueError):
        return False


class Printer:
    """Writes ``[label] line`` for every node, one colour per label, thread-safe."""

    def __init__(self, stdout: TextIO | None = None, stderr: TextIO | None = None) -> None:
        self.stdout = stdout or sys.stdout
        self.stderr = stderr or sys.stderr
        self.colour = use_colour(self.stdout)
        self._colours: dict[str, str] = {}
        self._lock = threading.Lock()

    def _prefix(self, label: str) -> str:
        if not self.colour:
            return f'[{label}]'
        code = self._colours.setdefault(label, _PALETTE[len(self._colours) % len(_PALETTE)])
        return f'\x1b[{code}m[{label}]\x1b[0m'

    def line(self, label: str, text: str, *, stderr: bool = False) -> None:
        """Print one line of a node's output."""
        stream = self.stderr if stderr else self.stdout
        with self._lock:
            try:
                stream.write(f'{self._prefix(label)} {text}\n')
                stream.flush()
            except (OSError, ValueError):  # closed terminal: the log file still has it
                pass


class LaunchLogFormatter(logging.Formatter):
    """``[INFO] [launch]: message`` as ros2 launch prints it; errors in red on a TTY."""

    def __init__(self, colour: bool = False) -> None:
        super().__init__()
        self.colour = colour

    def format(self, record: logging.LogRecord) -> str:
        text = f'[{record.levelname}] [{record.name}]: {record.getMessage()}'
        if self.colour and record.levelno >= logging.WARNING:
            code = _RED if record.levelno >= logging.ERROR else '33'
            text = f'\x1b[{code}m{text}\x1b[0m'
        return text


class _LaunchFileHandler(logging.FileHandler):
    """``logs/launch.log``: a full disk stops the file with one line on stderr, not a traceback
    per message (the console keeps every message)."""

    def handleError(self, record: logging.LogRecord) -> None:  # noqa: N802 (logging's name)
        exc = sys.exc_info()[1]
        if not isinstance(exc, OSError):
            super().handleError(record)
            return
        logging.getLogger('launch').removeHandler(self)
        with contextlib.suppress(OSError, ValueError):
            self.close()
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.write(f'[ERROR] [launch]: cannot write {self.baseFilename} '
                             f'({exc.strerror or exc}); launcher messages go to the console '
                             'only from here.\n')

    def close(self) -> None:
        with contextlib.suppress(OSError, ValueError):   # flush of a full disk at the end
            super().close()


def configure_launch_logger(log_file: Path | None) -> list[logging.Handler]:
    """Send the launcher's own messages to stderr and ``log_file``; returns the handlers added."""
    logger = logging.getLogger('launch')
    logger.setLevel(logging.INFO)
    logger.propagate = False
    handlers: list[logging.Handler] = []
    console = logging.StreamHandler(sys.stderr)
    console.setFormatter(LaunchLogFormatter(colour=use_colour(sys.stderr)))
    handlers.append(console)
    if log_file is not None:
        log_file.parent.mkdir(parents=True, exist_ok=True)
        file_handler = _LaunchFileHandler(log_file, encoding='utf-8')
        file_handler.setFormatter(logging.Formatter('%(asctime)s [%(levelname)s] %(message)s'))
        handlers.append(file_handler)
    for handler in handlers:
        logger.addHandler(handler)
    return handlers


def remove_handlers(handlers: list[logging.Handler]) -> None:
    """Undo :func:`configure_launch_logger`."""
    logger = logging.getLogger('launch')
    for handler in handlers:
        logger.removeHandler(handler)
        handler.close()
