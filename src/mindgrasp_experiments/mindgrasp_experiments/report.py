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

from mindgrasp_experiments.records import TrialRecord, read_records, write_records
from mindgrasp_experiments.summary import PAPER, summarise

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


def render_report(summary: Mapping[str, Any], run: Mapping[str, Any]) -> str:
    """report.md: our figures (with Wilson 95 % CIs) beside the paper's, speed, failures."""
    protocol = run.get('protocol', '')
    paper = PAPER.get(protocol, {})
    lines = [f"# {protocol.replace('_', ' ').capitalize() or 'Experiment'}: "
             f"{summary['trials']} trials, subject {run.get('subject', '?')}", '']
    settings = ', '.join(f'{k} {run[k]}' for k in ('seed', 'accuracy', 'realism', 'workers')
                         if k in run and run[k] is not None)
    if settings:
        lines += [f'Settings: {settings}. Command: `{run.get("command", "")}`', '']
    lines += ['| figure | ours | Wilson 95 % CI | paper |', '|---|---|---|---|']
    rows = [('grasp success (lifted above 0.22 m)', 'success'),
            ('correct object chosen', 'correct_choice'),
            ('correct and successful', 'correct_and_successful')]
    for label, key in rows:
        lines.append(f"| {label} | {_pct(summary.get(f'{key}_rate'))} "
                     f"({summary.get(f'{key}_count', 0)}/{summary['trials']}) | "
                     f"{_ci(summary.get(f'{key}_ci95'))} | {_pct(paper.get(f'{key}_rate'))} |")
    for shape, r in summary.get('success_by_shape', {}).items():
        if r['trials']:
            lines.append(f"| success, {shape} | {_pct(r['rate'])} ({r['count']}/{r['trials']}) "
                         f"| {_ci(r['ci95'])} | {_pct(paper.get(f'success_rate_{shape}'))} |")
    lines.append(f"| mean trial time | {_s(summary.get('mean_duration_s'))} | | "
                 f"{_s(paper.get('mean_duration_s'))} |")
    lines.append(f"| mean time to a successful grasp | {_s(summary.get('mean_time_to_grasp_s'))}"
                 f" (median {_s(summary.get('median_time_to_grasp_s'))}) | | |")
    certainty = summary.get('mean_certainty')
    certainty_text = ('n/a' if certainty is None or not math.isfinite(certainty)
                      else f'{certainty:.2f}')    # n/a: no decoder (oracle, autonomous)
    lines += ['', f"Decoder online accuracy against the subject's intent: "
              f"{_pct(summary.get('decoder_accuracy'))}; mean certainty {certainty_text}.", '']
    failures = summary.get('failures') or {}
    if failures:
        lines += ['Trials without a successful end, by kind: ' + ', '.join(
            f'{k} {v}' for k, v in sorted(failures.items())) + f" (node errors: "
            f"{summary.get('node_errors', 0)}).", '']
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
              run: Mapping[str, Any]) -> dict:
    """Write records, summary.json, report.md and the plots; returns the summary dict."""
    from mindgrasp_experiments.plots import write_plots

    run_dir = Path(run_dir)
    run_dir.mkdir(parents=True, exist_ok=True)
    write_records(records, run_dir)
    run = dict(run)
    run['plots'] = [p.name for p in write_plots(records, run_dir, run.get('protocol', ''))]
    summary = summarise(records)
    doc = {'summary': summary, 'run': run, 'paper': PAPER.get(run.get('protocol', ''), {})}
    (run_dir / 'summary.json').write_text(json.dumps(finite(doc), indent=2) + '\n',
                                          encoding='utf-8')
    (run_dir / 'report.md').write_text(render_report(summary, run), encoding='utf-8')
    return doc


def rebuild(run_dir: str | Path) -> dict:
    """Rebuild summary.json, report.md and the plots of ``run_dir`` from its records."""
    run_dir = Path(run_dir)
    records = read_records(run_dir)
    run: dict = {}
    if (run_dir / 'summary.json').exists():
        run = json.loads((run_dir / 'summary.json').read_text(encoding='utf-8')).get('run', {})
    if not run.get('protocol') and records:
        run['protocol'] = records[0].protocol
        run['subject'] = records[0].subject
    return write_run(run_dir, records, run)
