"""Publishing while readers come and go: cyclonedds-python's matched-endpoint list can be sized
before a new reader matches and filled after (IndexError); the runtime must not crash a node."""

from __future__ import annotations

from mindgrasp_ros.runtime.dds.participant import _matched


def test_matched_count_survives_a_reader_matching_between_the_two_calls() -> None:
    calls = []

    def handles() -> list[int]:
        calls.append(1)
        if len(calls) == 1:
            raise IndexError('invalid index')  # what cyclonedds-python raises in the race
        return [11, 12]

    assert _matched(handles) == 2 and len(calls) == 2

    def always_racing() -> list[int]:
        raise IndexError('invalid index')

    assert _matched(always_racing) == 1  # "at least one": the caller writes
