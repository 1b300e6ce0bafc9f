"""Names of the session's events, one definition for the LSL marker stream and the exports.

``prompt/<phase>/<class>``, ``target/<colour> <shape>``, ``result/success|failure/<object>`` and
``state/<n> <name>``: MNE selects annotations by their ``/``-separated tags, so the same strings
epoch a BIDS/FIF export, an XDF recorded by LabRecorder, or a bag (``epochs['success']``).
ROS-free.
"""

from __future__ import annotations

from .montage import class_name

__all__ = ['lsl_time', 'prompt_marker', 'result_marker', 'state_marker', 'target_marker']


def prompt_marker(phase: str, class_index: int) -> str:
    """``prompt/cue/left_hand``: a trainer prompt's phase and class (``rest`` for none)."""
    return f'prompt/{phase}/{class_name(int(class_index))}'


def target_marker(colour: str, shape: str) -> str:
    """``target/red cube``: the object the task asks for."""
    return f'target/{colour} {shape}'


def result_marker(success: bool, desired_object: str) -> str:
    """``result/success/red cube``: a grasp trial's outcome and the object it asked for."""
    return f"result/{'success' if success else 'failure'}/{desired_object}"


def state_marker(state: int, state_name: str) -> str:
    """``state/3 INITIAL_APPROACH``: the controller entered a state."""
    return f'state/{int(state)} {state_name}'


def lsl_time(stamp_ns: int, ros_now_ns: int, lsl_now: float) -> float:
    """LSL time (s, ``pylsl.local_clock()``) of an event stamped ``stamp_ns`` on the ROS clock.

    The event is as old on both clocks: ``lsl_now - (ros_now - stamp)``, with ``ros_now_ns`` and
    ``lsl_now`` read together (wall-clock ROS time; a live run).
    """
    return lsl_now - (ros_now_ns - stamp_ns) * 1e-9
