"""The live parameter changes of a run, one JSON object a line (``<run>/params/changes.jsonl``).

The recorder feeds it every ``/parameter_events`` message it records, and the values each node had
when the recorder first saw it (its parameter services), so that a change carries its old value::

    {"time_ns": 1764201234000000000, "node": "/fsm", "name": "lock_duration",
     "old": 1.0, "new": 2.5, "stamp_ns": 1764201233990000000}

``time_ns`` is the recorder's receive time, the log time of the same event in the bag (its
``/parameter_events``), so a report or a replay can line a change up with the recording;
``stamp_ns`` is the event's own stamp (the node's clock). ``old`` is ``null`` when the value
before is not known (a change before the recorder saw the node); a deleted parameter has ``new``
``null``. Declarations (``new_parameters``) are no change: they only set the value known. Each line
is flushed when written, so an interrupted run keeps every change up to then.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

__all__ = ['EVENT_TYPE', 'PARAMETER_EVENTS', 'ParameterChangeLog', 'read_changes']

#: the topic every ROS 2 node announces its parameter changes on, and its type
PARAMETER_EVENTS = '/parameter_events'
EVENT_TYPE = 'rcl_interfaces/msg/ParameterEvent'


class ParameterChangeLog:
    """Appends the changes of ``/parameter_events`` to a JSONL file.

    Parameters
    ----------
    path
        The file; its folder is created, an existing file is appended to.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file = self.path.open('a', encoding='utf-8')
        self._known: dict[tuple[str, str], Any] = {}
        self.count = 0

    def seed(self, node: str, values: Mapping[str, Any]) -> None:
        """Values of ``node``'s parameters read from the node itself (not a change); a value
        an event set already is kept (it is newer)."""
        for name, value in values.items():
            self._known.setdefault((node, name), value)

    def event(self, time_ns: int, stamp_ns: int, node: str, new: Mapping[str, Any],
              changed: Mapping[str, Any], deleted: Iterable[str]) -> list[dict[str, Any]]:
        """One ParameterEvent (values as Python values); returns the rows written (none after
        :meth:`close`)."""
        if self._file.closed:   # an event delivered while the recorder shuts down
            return []
        for name, value in new.items():
            self._known[(node, name)] = value
        rows = []
        for name, value in [*changed.items(), *((n, None) for n in deleted)]:
            old = self._known.get((node, name))
            rows.append({'time_ns': int(time_ns), 'node': node, 'name': name, 'old': old,
                         'new': value, 'stamp_ns': int(stamp_ns)})
            self._known[(node, name)] = value
        for row in rows:
            self._file.write(json.dumps(row) + '\n')
        if rows:
            self._file.flush()
            self.count += len(rows)
        return rows

    def close(self) -> None:
        """Close the file (every row is on disk already)."""
        self._file.close()


def read_changes(path: str | Path) -> list[dict[str, Any]]:
    """The rows of a changes file, in the order written (an unfinished last line is left out)."""
    rows = []
    for line in Path(path).read_text(encoding='utf-8').splitlines():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            break   # a run killed while writing: the lines before are whole
    return rows
