"""The controller's six states (numbers of ``mindgrasp_msgs/FsmState``), for the controller and
everyone who reads ``/fsm/state`` (virtual subject, trial manager, vision)."""

from __future__ import annotations

from enum import IntEnum

__all__ = ['STATE_NAMES', 'State']


class State(IntEnum):
    """The paper's six FSM states (same numbers as ``mindgrasp_msgs/FsmState``)."""

    OBJECT_SEARCH = 1
    CENTER_OBJECT = 2
    INITIAL_APPROACH = 3
    FINAL_APPROACH = 4
    GRASP_OBJECT = 5
    RETURN_TO_START = 6


#: the paper's state names
STATE_NAMES: dict[State, str] = {
    State.OBJECT_SEARCH: 'Object Search',
    State.CENTER_OBJECT: 'Center Object',
    State.INITIAL_APPROACH: 'Initial Approach',
    State.FINAL_APPROACH: 'Final Approach',
    State.GRASP_OBJECT: 'Grasp Object',
    State.RETURN_TO_START: 'Return to Start',
}
