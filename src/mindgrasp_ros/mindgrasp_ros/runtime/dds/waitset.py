"""An executor's DDS wait set: one ReadCondition per watched reader and a guard condition.

Each ReadCondition is attached with a key of ours (``WaitSet.attach`` passes its own), so that a
wait names the readers whose condition fired and the executor takes from those only: a take from
an empty reader costs ~5 us, and a node with a dozen readers (its parameter services count) woke
~150 times a second into ~15 of them for each message.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING

from cyclonedds.core import (
    DDSException,
    GuardCondition,
    InstanceState,
    ReadCondition,
    SampleState,
    ViewState,
    WaitSet,
)
from cyclonedds.internal import dds_c_t

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.dds.participant import DdsParticipant, DdsReader

__all__ = ['DdsWaitSet']

_ANY = SampleState.Any | ViewState.Any | InstanceState.Any


class DdsWaitSet:
    """Waits on the readers it watches (:meth:`watch`) and on :meth:`trigger`."""

    def __init__(self, dds: DdsParticipant) -> None:
        self._waitset = WaitSet(dds.participant)
        self._guard = GuardCondition(dds.participant)
        self._waitset.attach(self._guard)
        self._conditions: dict[int, tuple[DdsReader, ReadCondition]] = {}   # id(reader) ->
        self._reader_of_key: dict[int, int] = {}    # WaitSet attach key -> id(reader)
        self._keys = itertools.count(1)

    def watch(self, readers: dict[int, DdsReader]) -> None:
        """Watch exactly ``readers`` (by ``id(reader)``): detach the others, attach the new."""
        for key in list(self._conditions):
            if key not in readers:
                _reader, cond = self._conditions.pop(key)
                self._reader_of_key = {k: r for k, r in self._reader_of_key.items() if r != key}
                self._detach(cond)
        for key, reader in readers.items():
            if key not in self._conditions:
                cond = ReadCondition(reader.reader, _ANY)
                # WaitSet.detach still finds it in `attached`
                attach_key = next(self._keys)
                ret = self._waitset._waitset_attach(self._waitset._ref, cond._ref, attach_key)
                if ret < 0:
                    raise DDSException(ret, 'Occurred while attaching a ReadCondition')
                self._waitset.attached.append((cond, None))
                self._reader_of_key[attach_key] = key
                self._conditions[key] = (reader, cond)

    def _detach(self, cond: ReadCondition) -> None:
        try:
            self._waitset.detach(cond)
            cond.__del__()
        except Exception:
            pass

    def release(self) -> None:
        """Detach every reader's condition (the executor shuts down)."""
        for _reader, cond in self._conditions.values():
            self._detach(cond)
        self._conditions.clear()
        self._reader_of_key.clear()

    def trigger(self) -> None:
        """Make a wait return at once (the guard condition); harmless after the participant is
        gone."""
        try:
            self._guard.set(True)
        except Exception:
            pass

    def clear_trigger(self) -> None:
        """Reset the guard condition after a wait."""
        if self._guard.read():
            self._guard.set(False)

    def wait(self, timeout_ns: int) -> set[int] | None:
        """Wait up to ``timeout_ns`` (0: just look); the ids of the readers whose condition fired
        (None when it cannot tell: every reader is then taken from)."""
        n = len(self._conditions) + 2
        keys = (dds_c_t.attach * n)()
        count = self._waitset._waitset_wait(self._waitset._ref, keys, n, timeout_ns)
        if count < 0:
            raise DDSException(count, f'Occurred while waiting in {self._waitset!r}')
        if count > n:
            return None
        return {self._reader_of_key[k] for k in keys[:count] if k in self._reader_of_key}
