"""The comparison report of a replay: recorded vs replayed predictions and controller states.

Files written into the replay directory:

    report.md          what was replayed, agreement per topic, first divergence, notes
    comparison.json    the same figures, machine-readable (``mindgrasp replay --json`` prints it)
    predictions.csv    one row per prediction stamp: recorded and replayed class and certainty
    states.csv         (controller replayed) recorded and replayed state on a 0.1 s grid
    timeline.png       classes and states over time, recorded vs replayed, first divergence
    replayed_bag/      the replayed outputs as a rosbag2 bag
    params/            the parameter files the replayed nodes ran with

Predictions are paired by their stamp (the end of the decoded window, ns), which the classifier
derives from the recorded chunk stamps; a recorded prediction is comparable when its whole
window lies in the EEG that was fed. Agreement = comparable recorded predictions with a replayed
prediction of the same stamp and class / comparable recorded predictions.
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mindgrasp_bringup.replay.engine import ReplayResult
from mindgrasp_ros.topics import BCI_PREDICTION, FSM_STATE

__all__ = ['compare', 'write_report']

STATE_GRID_S = 0.1
OPEN_LOOP = ('The controller ran open loop: its arm and gripper commands went nowhere, and the '
             'joint states, camera images and detections it read are the recorded ones, which '
             'followed the recorded arm, not the replayed one. The states agree while the '
             'replayed controller decides as the recorded one did; after the first divergence '
             'its inputs no longer answer its own commands, so later differences say little.')


@dataclass
class _Pred:
    stamp_ns: int
    class_index: int
    certainty: float
    window_ns: int


def _predictions(messages: list[tuple[int, bytes]], store: Any) -> dict[int, _Pred]:
    out: dict[int, _Pred] = {}
    for _, data in messages:
        msg = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/MIPrediction')
        stamp = int(msg.header.stamp.sec) * 1_000_000_000 + int(msg.header.stamp.nanosec)
        out[stamp] = _Pred(stamp, int(msg.class_index), float(msg.certainty),
                           round(float(msg.window_length) * 1e9))
    return out


def _states(messages: list[tuple[int, bytes]], store: Any) -> list[tuple[int, int, str]]:
    out = []
    for t_ns, data in messages:
        msg = store.deserialize_cdr(data, 'mindgrasp_msgs/msg/FsmState')
        out.append((t_ns, int(msg.state), str(msg.state_name)))
    return sorted(out, key=lambda s: s[0])


def _state_at(states: list[tuple[int, int, str]], times: np.ndarray) -> np.ndarray:
    """State (0 = none yet) in force at each time (ns)."""
    if not states:
        return np.zeros(len(times), dtype=int)
    t = np.array([s[0] for s in states], dtype=np.int64)
    v = np.array([s[1] for s in states], dtype=int)
    idx = np.searchsorted(t, times, side='right') - 1
    return np.where(idx >= 0, v[np.clip(idx, 0, None)], 0)


def compare(result: ReplayResult, store: Any) -> dict[str, Any]:
    """Agreement per topic and first divergences (times in s from the bag start)."""
    t0 = result.start_ns
    summary: dict[str, Any] = {
        'bag': str(result.bag), 'run_dir': str(result.run_dir) if result.run_dir else None,
        'replay_dir': str(result.output), 'nodes': result.nodes,
        'clock': 'bag (lock-step: every recorded input at its recorded time)',
        'open_loop': 'controller' in result.nodes, 'fed': result.fed,
        'skipped_eeg_chunks': result.skipped_eeg_chunks, 'topics': {}, 'notes': result.notes,
        'damage': result.damage,
        'parameter_changes': result.parameter_changes,
    }
    rec = _predictions(result.recorded.get(BCI_PREDICTION.name, []), store)
    rep = _predictions(result.replayed.get(BCI_PREDICTION.name, []), store)
    lo, hi = result.first_fed_eeg_ns, result.last_fed_eeg_ns
    tol = 5_000_000  # ns: about a sample at 250 Hz
    comparable = sorted(s for s, p in rec.items() if lo is not None and hi is not None
                        and s - p.window_ns + tol >= lo and s <= hi + tol)
    agree = [s for s in comparable if s in rep and rep[s].class_index == rec[s].class_index]
    first_div = next((s for s in comparable if s not in rep
                      or rep[s].class_index != rec[s].class_index), None)
    cert = [abs(rep[s].certainty - rec[s].certainty) for s in comparable if s in rep]
    pred: dict[str, Any] = {
        'recorded': len(rec), 'replayed': len(rep), 'comparable': len(comparable),
        'agree': len(agree), 'missing': sum(1 for s in comparable if s not in rep),
        'not_comparable': len(rec) - len(comparable),
        'extra': sum(1 for s in rep if s not in rec),
        'agreement': len(agree) / len(comparable) if comparable else None,
        'max_certainty_difference': max(cert) if cert else None,
        'first_divergence': None,
    }
    if first_div is not None:
        what = ('no replayed prediction' if first_div not in rep else
                f'class {rec[first_div].class_index} recorded, '
                f'{rep[first_div].class_index} replayed')
        pred['first_divergence'] = {'time_s': (first_div - t0) / 1e9, 'stamp_ns': first_div,
                                    'what': what}
    summary['topics'][BCI_PREDICTION.name] = pred
    summary['prediction_agreement'] = pred['agreement'] if comparable else 0.0
    summary['_predictions'] = (rec, rep, comparable)
    if FSM_STATE.name in result.replayed:
        rs = _states(result.recorded.get(FSM_STATE.name, []), store)
        ps = _states(result.replayed[FSM_STATE.name], store)
        grid = np.arange(t0, result.end_ns + 1, round(STATE_GRID_S * 1e9), dtype=np.int64)
        a, b = _state_at(rs, grid), _state_at(ps, grid)
        both = (a > 0) & (b > 0)
        same = both & (a == b)
        diverge = np.nonzero(both & (a != b))[0]
        state: dict[str, Any] = {
            'recorded_messages': len(rs), 'replayed_messages': len(ps),
            'agreement': float(same.sum() / both.sum()) if both.any() else None,
            'grid_s': STATE_GRID_S, 'first_divergence': None, 'open_loop': True,
        }
        if len(diverge):
            i = int(diverge[0])
            state['first_divergence'] = {
                'time_s': (int(grid[i]) - t0) / 1e9,
                'what': f'state {a[i]} recorded, {b[i]} replayed'}
        summary['topics'][FSM_STATE.name] = state
        summary['state_agreement'] = state['agreement']
        summary['_states'] = (grid, a, b)
    return summary


def _fmt(x: float | None, pct: bool = True) -> str:
    if x is None:
        return 'n/a'
    return f'{100 * x:.1f} %' if pct else f'{x:.3g}'


def write_report(result: ReplayResult, store: Any) -> dict[str, Any]:
    """Write every report file; returns the summary (also in comparison.json)."""
    out = result.output
    summary = compare(result, store)
    rec, rep, comparable = summary.pop('_predictions')
    states = summary.pop('_states', None)
    t0 = result.start_ns
    comparable_set = set(comparable)
    with (out / 'predictions.csv').open('w', newline='') as f:
        w = csv.writer(f)
        w.writerow(['time_s', 'stamp_ns', 'recorded_class', 'replayed_class',
                    'recorded_certainty', 'replayed_certainty', 'comparable', 'agree'])
        for s in sorted(set(rec) | set(rep)):
            r, p = rec.get(s), rep.get(s)
            w.writerow([f'{(s - t0) / 1e9:.6f}', s, r.class_index if r else '',
                        p.class_index if p else '', f'{r.certainty:.6g}' if r else '',
                        f'{p.certainty:.6g}' if p else '', int(s in comparable_set),
                        int(bool(r and p and r.class_index == p.class_index))])
    files = ['report.md', 'comparison.json', 'predictions.csv', 'timeline.png',
             'replayed_bag', 'params']
    if states is not None:
        grid, a, b = states
        with (out / 'states.csv').open('w', newline='') as f:
            w = csv.writer(f)
            w.writerow(['time_s', 'recorded_state', 'replayed_state'])
            for t, x, y in zip(grid, a, b, strict=True):
                w.writerow([f'{(int(t) - t0) / 1e9:.3f}', int(x), int(y)])
        files.insert(3, 'states.csv')
    _plot(out / 'timeline.png', rec, rep, states, summary, t0)
    summary['files'] = files
    summary['report_path'] = str(out / 'report.md')
    (out / 'report.md').write_text(_markdown(summary))
    (out / 'comparison.json').write_text(json.dumps(summary, indent=2) + '\n')
    result.summary = summary
    result.report_path = out / 'report.md'
    return summary


def _markdown(s: dict[str, Any]) -> str:
    pred = s['topics'][BCI_PREDICTION.name]
    lines = [
        '# Replay report', '',
        f'- Run: `{s["run_dir"] or s["bag"]}`',
        f'- Nodes re-run: {", ".join(s["nodes"])} (same node classes, lock-step on the bag '
        'clock: every recorded input at its recorded time)',
        '- Inputs fed: ' + ', '.join(f'{t} ({n})' for t, n in s['fed'].items()),
        '', '## Agreement per topic', '',
        '| topic | recorded | replayed | compared | agreement | first divergence |',
        '|---|---|---|---|---|---|',
    ]
    div = pred['first_divergence']
    lines.append(f'| /bci/prediction | {pred["recorded"]} | {pred["replayed"]} | '
                 f'{pred["comparable"]} | {_fmt(pred["agreement"])} | '
                 + (f'{div["time_s"]:.3f} s: {div["what"]}' if div else 'none') + ' |')
    state = s['topics'].get(FSM_STATE.name)
    if state is not None:
        div = state['first_divergence']
        lines.append(f'| /fsm/state (open loop) | {state["recorded_messages"]} msgs | '
                     f'{state["replayed_messages"]} msgs | {state["grid_s"]} s grid | '
                     f'{_fmt(state["agreement"])} | '
                     + (f'{div["time_s"]:.3f} s: {div["what"]}' if div else 'none') + ' |')
    lines += ['', f'Predictions: {pred["agree"]} of {pred["comparable"]} comparable recorded '
              f'predictions agree; {pred["missing"]} have no replayed prediction; '
              f'{pred["not_comparable"]} recorded predictions lie outside the fed EEG; '
              f'{pred["extra"]} replayed predictions were not recorded (the recorder missed '
              'them, or the classifier decided where it did not live). Largest certainty '
              f'difference: {_fmt(pred["max_certainty_difference"], pct=False)}.']
    if s['skipped_eeg_chunks']:
        lines += ['', f'{s["skipped_eeg_chunks"]} recorded EEG chunk(s) were not fed, to start '
                  'the classifier on the samples where the live one (re)started.']
    if state is not None:
        lines += ['', '## Controller replayed open loop', '', OPEN_LOOP]
    else:
        lines += ['', 'The controller was not re-run (`--controller` re-runs it, open loop).']
    if s['notes']:
        lines += ['', '## Notes', ''] + [f'- {n}' for n in s['notes']]
    lines += ['', '## Files', ''] + [f'- `{f}`' for f in s['files']]
    lines += ['', '![timeline](timeline.png)', '']
    return '\n'.join(lines)


def _plot(path: Path, rec: dict, rep: dict, states: Any, summary: dict[str, Any],
          t0: int) -> None:
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    rows = 2 if states is not None else 1
    fig, axes = plt.subplots(rows, 1, figsize=(10, 2.6 * rows), sharex=True, squeeze=False)
    ax = axes[0][0]
    for preds, marker, label, offset in ((rec, 'o', 'recorded', 0.08),
                                         (rep, 'x', 'replayed', -0.08)):
        if preds:
            t = np.array([(s - t0) / 1e9 for s in sorted(preds)])
            c = np.array([preds[s].class_index for s in sorted(preds)])
            ax.plot(t, c + offset, marker, ms=3, ls='none', label=label)
    ax.set_yticks(range(4), ['left hand', 'right hand', 'both hands', 'both feet'])
    ax.set_title(f'/bci/prediction: agreement '
                 f'{_fmt(summary["topics"][BCI_PREDICTION.name]["agreement"])}')
    ax.legend(loc='upper right', fontsize=8)
    div = summary['topics'][BCI_PREDICTION.name]['first_divergence']
    if div:
        ax.axvline(div['time_s'], color='r', ls='--', lw=1)
    if states is not None:
        grid, a, b = states
        t = (grid - t0) / 1e9
        ax = axes[1][0]
        ax.step(t, a, where='post', label='recorded')
        ax.step(t, b, where='post', ls='--', label='replayed (open loop)')
        ax.set_yticks(range(1, 7), ['search', 'center', 'approach', 'final', 'grasp', 'return'])
        ax.set_title(f'/fsm/state: agreement '
                     f'{_fmt(summary["topics"][FSM_STATE.name]["agreement"])} (open loop)')
        ax.legend(loc='upper right', fontsize=8)
        div = summary['topics'][FSM_STATE.name]['first_divergence']
        if div:
            ax.axvline(div['time_s'], color='r', ls='--', lw=1)
    axes[-1][0].set_xlabel('time since the bag start (s)')
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
