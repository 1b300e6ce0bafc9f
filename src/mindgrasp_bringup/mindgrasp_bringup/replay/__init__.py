"""Replay a recorded run as an experiment on recorded data (:mod:`.engine`) and compare what the
re-run nodes decide with what they decided live (:mod:`.report`).

Entry points: ``mindgrasp replay RUN`` (:mod:`mindgrasp_bringup.commands.replay`) and
``mindgrasp launch replay bag:=RUN`` (:mod:`.replay_node`).
"""

from mindgrasp_ros.topics import BCI_PREDICTION, FSM_STATE

from .engine import ReplayConfig, ReplayResult, replay
from .report import compare, write_report

__all__ = ['ReplayConfig', 'ReplayResult', 'compare', 'damage_lines', 'replay', 'run_replay',
           'write_report']


def run_replay(cfg: ReplayConfig) -> ReplayResult:
    """Replay and write the comparison report (``result.summary``, ``result.report_path``)."""
    from mindgrasp_bag.typestore import typestore

    result = replay(cfg)
    write_report(result, typestore())
    return result


def summary_line(result: ReplayResult) -> str:
    """One line: agreement per topic and where the report is."""
    s = result.summary
    pred = s['topics'][BCI_PREDICTION.name]
    parts = [f'predictions {pred["agree"]}/{pred["comparable"]} agree '
             f'({100 * (pred["agreement"] or 0):.1f} %)']
    state = s['topics'].get(FSM_STATE.name)
    if state is not None:
        parts.append(f'controller states {100 * (state["agreement"] or 0):.1f} % (open loop)')
    return f'Replayed {", ".join(result.nodes)}: ' + '; '.join(parts) + \
        f'; report: {result.report_path}'


def damage_lines(result: ReplayResult, allow_damaged: bool) -> list[str]:
    """What a damaged bag cost the replay, one line per problem then the counts ([] when the
    bag is sound). Without ``allow_damaged`` the caller exits 1 (the bag tools' policy)."""
    damage = result.damage
    if not damage.get('damaged'):
        return []
    end = '.' if allow_damaged else '; pass --allow-damaged (allow_damaged:=true) to accept it.'
    return [*(f'damaged bag: {p}' for p in damage['problems']),
            f'damaged bag: {damage["summary"]} The agreement covers the readable part only{end}']
