"""Live parameter changes of a recorded run, applied again in a replay at their recorded times.

The bag's ``/parameter_events`` (recorded with the run) say which node changed which parameter
when (the log time, on the replay's bag clock). Changes of a re-run node (``/classifier``,
``/fsm``) are applied to it with ``set_parameters`` once the replay clock reaches that time, so
the replayed node decides with the values the live one had; a parameter the user overrode
(``-p node.name:=value``) keeps the override. Changes of other nodes are left alone (their
outputs are recorded inputs of the replay).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from mindgrasp_bag.param_changes import EVENT_TYPE

__all__ = ['ParameterChange', 'apply_change', 'recorded_changes']


@dataclass(frozen=True)
class ParameterChange:
    """One recorded change: log time (ns, bag clock), node (``/fsm``), name, new value."""

    time_ns: int
    node: str
    name: str
    value: Any


def recorded_changes(events: list[tuple[int, bytes]], store: Any, nodes: set[str],
                     overridden: set[tuple[str, str]]) -> list[ParameterChange]:
    """The changes of ``nodes`` in recorded ``/parameter_events`` ``(log time ns, CDR)``, in time
    order; ``overridden`` holds ``(node, name)`` the user set for the replay."""
    from mindgrasp_ros.runtime.parameter import parameter_value_to_python

    out = []
    for t_ns, data in events:
        msg = store.deserialize_cdr(data, EVENT_TYPE)
        if msg.node not in nodes:
            continue
        out += [ParameterChange(t_ns, msg.node, p.name, parameter_value_to_python(p.value))
                for p in msg.changed_parameters if (msg.node, p.name) not in overridden]
    return sorted(out, key=lambda c: c.time_ns)


def apply_change(node: Any, change: ParameterChange, now_ns: int) -> dict[str, Any]:
    """Set the parameter on the re-run node; the row the replay summary keeps."""
    from mindgrasp_ros.runtime.parameter import Parameter

    result = node.set_parameters([Parameter(change.name, value=change.value)])[0]
    return {'time_ns': change.time_ns, 'applied_ns': now_ns, 'node': change.node,
            'name': change.name, 'value': change.value, 'successful': bool(result.successful),
            'reason': result.reason}
