"""The run directory of an experiment: records, summary.json, report.md and plots.

    write_run(run_dir, records, run_info)   # records.csv/.parquet, summary.json, report.md, plots
    rebuild(run_dir)                        # summary and report again from the records

``run_info`` holds what the records cannot tell: the command, protocol, subject, seed, workers,
simulated and wall seconds, CPU seconds, time per node.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_common.safe_files import write_atomic
from mindgrasp_experiments.records import TrialRecord, read_records, write_records
from mindgrasp_experiments.summary import (
    PAPER,
    answer_summary,
    calibration_accuracy_of,
    summarise,
)

__all__ = ['finite', 'rebuild', 'render_report', 'write_run']


def finite(value: Any) -> Any:
    """NaN and infinities -> None, recursively, so the JSON is strict JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, Mapping):
        return {k: finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite(v) for v in value]
    return value


def _pct(rate: float | None) -> str:
    return 'n/a' if rate is None or not math.isfinite(rate) else f'{100 * rate:.1f} %'


def _ci(ci: Sequence[float] | None) -> str:
    if not ci or ci[0] is None or not math.isfinite(ci[0]):
        return ''
    return f'{100 * ci[0]:.1f}-{100 * ci[1]:.1f} %'


def _s(value: float | None) -> str:
    return 'n/a' if value is None or not math.isfinite(value) else f'{value:.1f} s'


def _rate_row(label: str, summary: Mapping[str, Any], key: str, paper: Mapping[str, Any]) -> str:
    """A table row of the rate ``<key>_rate`` with its count, Wilson CI and the paper's."""
    return (f"| {label} | {_pct(summary.get(f'{key}_rate'))} "
            f"({summary.get(f'{key}_count', 0)}/{summary['trials']}) | "
            f"{_ci(summary.get(f'{key}_ci95'))} | {_pct(paper.get(f'{key}_rate'))} |")


def _itr_text(summary: Mapping[str, Any]) -> str:
    itr = summary.get('itr_bits_per_min')
    if itr is None or not math.isfinite(itr):
        return 'n/a'
    bits = summary.get('itr_bits_per_selection')
    each = f', {bits:.2f} bits each' if bits is not None and math.isfinite(bits) else ''
    return f"{itr:.2f} bits/min ({summary.get('selections', 0)} selections{each})"


def _answer_lines(summary: Mapping[str, Any]) -> list[str]:
    """The person's answer pair and the calibration gate's prediction beside the measured
    figures (nothing for a run without a scan answer pair)."""
    pair = summary.get('answer_pair') or ''
    if not pair:
        return []
    from mindgrasp_common.answer_pair import answer_pair
    from mindgrasp_common.errors import CommonError

    try:
        said = '; '.join(answer_pair(p).describe() for p in pair.split(','))
    except CommonError:
        said = ''
    lines = [f'Answer pair **{pair}**' + (f' ({said})' if said else '') + '.']
    verdict = summary.get('gate_verdict') or ''
    if verdict:
        lines += ['', f"Calibration gate: **{verdict}** ({summary.get('gate_reason', '')}).", '',
                  '| predicted at calibration | predicted | measured |', '|---|---|---|',
                  f"| correct grasp | {_pct(summary.get('predicted_correct_rate'))} | "
                  f"{_pct(summary.get('correct_and_successful_rate'))} |",
                  f"| wrong grasp | {_pct(summary.get('predicted_wrong_rate'))} | "
                  f"{_pct(summary.get('wrong_grasp_rate'))} |",
                  f"| time per decision (offer) | {_s(summary.get('predicted_decision_time_s'))}"
                  ' | |']
        if verdict != 'ready':
            lines += ['', f'Warning: the calibration gate did not call this person ready '
                          f'({verdict}); the figures show what the loop gave anyway.']
    return [*lines, '']


def render_report(summary: Mapping[str, Any], run: Mapping[str, Any]) -> str:
    """report.md: our figures (with Wilson 95 % CIs) beside the paper's, the three outcomes,
    the selection's information transfer rate, the decoder's online accuracy beside its
    calibration estimate, speed, failures."""
    protocol = run.get('protocol', '')
    paper = PAPER.get(protocol, {})
    interrupted = summary.get('interrupted_trials') or 0
    lines = [f"# {protocol.replace('_', ' ').capitalize() or 'Experiment'}: "
             f"{summary['trials']} trials"
             + (f' (and {interrupted} interrupted)' if interrupted else '')
             + f", subject {run.get('subject', '?')}", '']
    settings = ', '.join(f'{k} {run[k]}' for k in ('seed', 'accuracy', 'realism', 'workers')
                         if k in run and run[k] is not None)
    if settings:
        lines += [f'Settings: {settings}. Command: `{run.get("command", "")}`', '']
    lines += ['| figure | ours | Wilson 95 % CI | paper |', '|---|---|---|---|']
    rows = [('grasp success (lifted above 0.22 m)', 'success'),
            ('correct object chosen', 'correct_choice'),
            ('outcome **correct grasp**: the desired object lifted (correct and successful)',
             'correct_and_successful'),
            ('outcome **wrong grasp**: another object lifted, or a grasp closed on one',
             'wrong_grasp'),
            ('outcome **no grasp**: timeout, stall, cancelled, nothing attempted', 'no_grasp')]
    lines += [_rate_row(label, summary, key, paper) for label, key in rows]
    for shape, r in summary.get('success_by_shape', {}).items():
        if r['trials']:
            lines.append(f"| success, {shape} | {_pct(r['rate'])} ({r['count']}/{r['trials']}) "
                         f"| {_ci(r['ci95'])} | {_pct(paper.get(f'success_rate_{shape}'))} |")
    lines.append(f"| mean trial time | {_s(summary.get('mean_duration_s'))} | | "
                 f"{_s(paper.get('mean_duration_s'))} |")
    lines.append(f"| mean time to a successful grasp | {_s(summary.get('mean_time_to_grasp_s'))}"
                 f" (median {_s(summary.get('median_time_to_grasp_s'))}) | | |")
    lines.append(f"| median time to a correct grasp | "
                 f"{_s(summary.get('median_time_to_correct_grasp_s'))} | | |")
    p_sel = summary.get('selection_accuracy')
    p_text = 'n/a' if p_sel is None or not math.isfinite(p_sel) else f'{p_sel:.2f}'
    lines.append(f"| information transfer rate (Wolpaw; N = {summary.get('itr_choices', '?')} "
                 f"objects, P = {p_text} correct of the grasps) | {_itr_text(summary)} | | |")
    windows = summary.get('online_windows') or 0
    lines.append(f"| decoder online accuracy (classifier windows against the subject's intent) "
                 f"| {_pct(summary.get('online_accuracy'))} of {windows} windows | "
                 f"{_ci(summary.get('online_accuracy_ci95'))} | |")
    lines.append(f"| decoder calibration accuracy (the model's cross-validation) | "
                 f"{_pct(summary.get('calibration_accuracy'))} | | |")
    certainty = summary.get('mean_certainty')
    certainty_text = ('n/a' if certainty is None or not math.isfinite(certainty)
                      else f'{certainty:.2f}')    # n/a: no decoder (oracle, autonomous)
    lines += ['', f"Decoder per decision (the most frequent class over one held intent): "
              f"{_pct(summary.get('online_decision_accuracy'))} of "
              f"{summary.get('online_decisions') or 0}; mean certainty {certainty_text}.", '']
    lines += _answer_lines(summary)
    failures = summary.get('failures') or {}
    if failures:
        lines += ['Trials without a successful end, by kind: ' + ', '.join(
            f'{k} {v}' for k, v in sorted(failures.items())) + f" (node errors: "
            f"{summary.get('node_errors', 0)}).", '']
    if summary.get('cancels'):
        lines += [f"The person cancelled {summary['cancels']} approach(es) (a cancelled trial "
                  'is a no grasp unless a later attempt grasps).', '']
    if interrupted:
        lines += [f'{interrupted} interrupted trial(s) (Ctrl-C) are left out of every figure.',
                  '']
    if 'real_time_factor' in run:
        lines += ['## Speed', '',
                  f"Simulated {run['sim_s']:.0f} s in {run['wall_s']:.0f} s of wall time with "
                  f"{run.get('workers', 1)} worker(s): real-time factor "
                  f"**{run['real_time_factor']:.1f}**, {run['cpu_s_per_sim_s']:.3f} CPU s per "
                  'simulated s.', '']
        node_s = run.get('node_s') or {}
        total = sum(node_s.values())
        if total > 0:
            lines += ['Where the time goes (wall s in each node\'s callbacks, all trials):', '',
                      '| node | s | share |', '|---|---|---|']
            for name, sec in sorted(node_s.items(), key=lambda kv: -kv[1]):
                lines.append(f'| {name} | {sec:.1f} | {100 * sec / total:.0f} % |')
            lines.append('')
    if run.get('interrupted'):
        lines += ['**Interrupted**: partial records (Ctrl-C).', '']
    lines += ['Plots: ' + ', '.join(f'[{p}]({p})' for p in run.get('plots', [])), '',
              'Records: records.csv, records.parquet (one row per trial). Rebuild this report '
              'with `mindgrasp experiment report <run dir>`.', '']
    return '\n'.join(lines)


def write_run(run_dir: str | Path, records: Sequence[TrialRecord],
              run: Mapping[str, Any], calibration_accuracy: float | None = None, *,
              with_records: bool = True) -> dict:
    """Write records, summary.json, report.md and the plots; returns the summary document.

    ``with_records=False`` leaves the record files as they are (a rebuild from them).

    ``calibration_accuracy``: the classifier's cross-validated accuracy, shown beside its
    online accuracy; by default ``run['calibration_accuracy']``, else read from the model the
    run's ``params/classifier.yaml`` names (:func:`~.summary.calibration_accuracy_of`)."""
    from mindgrasp_experiments.plots import write_plots

    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    if with_records:
        write_records(records, run_dir)
    run = dict(run)
    run['plots'] = [p.name for p in write_plots(records, run_dir, run.get('protocol', ''))]
    if calibration_accuracy is None:
        calibration_accuracy = run.get('calibration_accuracy')
    if calibration_accuracy is None:
        calibration_accuracy = calibration_accuracy_of(run_dir)
    summary = summarise(records, calibration_accuracy)
    summary.update(answer_summary(run_dir, records))
    doc = {'summary': summary, 'run': run, 'paper': PAPER.get(run.get('protocol', ''), {})}
    text = json.dumps(finite(doc), indent=2) + '\n'
    write_atomic(run_dir / 'summary.json', lambda tmp: tmp.write_text(text, encoding='utf-8'))
    report = render_report(summary, run)
    write_atomic(run_dir / 'report.md', lambda tmp: tmp.write_text(report, encoding='utf-8'))
    return doc


def rebuild(run_dir: str | Path) -> dict:
    """Rebuild summary.json, report.md and the plots of ``run_dir`` from its records (which
    are read, never rewritten)."""
    run_dir = Path(run_dir)
    records = read_records(run_dir)
    run: dict = {}
    if (run_dir / 'summary.json').exists():
        run = json.loads((run_dir / 'summary.json').read_text(encoding='utf-8')).get('run', {})
    if not run.get('protocol') and records:
        run['protocol'] = records[0].protocol
        run['subject'] = records[0].subject
    return write_run(run_dir, records, run, with_records=False)
