"""Accuracy sweeps: the set-locations protocol at several BCI accuracies (and parameter values).

Each point of a sweep is an ordinary experiment run (records, summary.json, report.md and plots
written by :func:`mindgrasp_experiments.report.write_run`) in ``<out>/points/<point>/``; this
module turns the points into one table (``sweep.csv``, ``sweep.json``), the sweep plots (success
and time to grasp against accuracy, PNG and SVG) and ``report.md``.

Per point, under the names of :func:`~mindgrasp_experiments.summary.summarise`: grasp success,
correct choice and the three outcomes (``correct_and_successful_rate`` = correct grasp,
``wrong_grasp_rate``, ``no_grasp_rate``; Wilson 95 % CIs), ``median_time_to_correct_grasp_s``,
the selection's ``itr_bits_per_min``, and the decoder's realised ``online_accuracy`` against the
subject's intent, over classifier windows and over decisions (a decision: the most frequent
decoded class over one span of a held intent), each with its Wilson 95 % CI, beside its
``calibration_accuracy``; and the mean time to a successful grasp (``mean_time_s``, Student-t
95 % CI).

    >>> parse_accuracies('0.3,0.55,1')
    [0.3, 0.55, 1.0]
    >>> parse_param('fsm.certainty_threshold=0.3,0.5')
    ('fsm', 'certainty_threshold', ['0.3', '0.5'])
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import re
import statistics
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.records import TrialRecord
from mindgrasp_experiments.report import finite
from mindgrasp_experiments.summary import counted, summarise
from mindgrasp_ros.graph.spec import NodeSpec

__all__ = ['SUMMARY_KEYS', 'Param', 'apply_params', 'check_params', 'combinations',
           'parse_accuracies', 'parse_param', 'parse_seeds', 'parse_subjects', 'point_figures',
           'point_name', 'write_sweep']

#: ``node.parameter=v1,v2,...``
Param = tuple[str, str, list[str]]

_PARAM = re.compile(r'^([A-Za-z_][\w]*)\.([A-Za-z_][\w.]*)=(.+)$')
#: characters a point's directory name keeps (a subject file's path has slashes)
_UNSAFE = re.compile(r'[^\w.+-]')


def _each_once(values: list, option: str, text: str, what: str) -> list:
    """``values``, or :class:`ExperimentError` when one is given twice."""
    if len(set(values)) != len(values):
        msg = f'{option} {text} repeats {what}; give each once.'
        raise ExperimentError(msg)
    return values


def _numbers(text: str, option: str, convert, valid, unreadable: str, invalid: str,
             what: str) -> list:
    """Comma-separated numbers of ``option``, each converted, checked by ``valid`` and given
    once; ``unreadable`` / ``invalid`` (with ``{part}``) name a bad one and the fix."""
    out = []
    for part in text.split(','):
        try:
            value = convert(part)
        except ValueError:
            raise ExperimentError(f'{option}: ' + unreadable.format(part=part.strip())) from None
        if not valid(value):
            raise ExperimentError(f'{option}: ' + invalid.format(part=part.strip()))
        out.append(value)
    return _each_once(out, option, text, what)


def parse_accuracies(text: str) -> list[float]:
    """``'0.3,0.4,1.0'`` -> accuracies, each within (0, 1] (a probability of the right class)."""
    return _numbers(text, '--accuracy', float, lambda v: 0.0 < v <= 1.0 and math.isfinite(v),
                    '{part!r} is not a number; give accuracies within (0, 1] separated by '
                    'commas, e.g. 0.3,0.55,1.0.',
                    '{part} is outside (0, 1]; an accuracy is the probability that the subject '
                    'imagines the right class, e.g. 0.3,0.55,1.0.', 'an accuracy')


def parse_subjects(text: str) -> list[str]:
    """``'virtual,eegmmidb:1,s02.yaml'`` -> the subjects of a sweep, each once (each checked by
    :func:`mindgrasp_experiments.cli.subject_type` where the command parses it)."""
    out = [part.strip() for part in text.split(',')]
    if not all(out):
        msg = (f'--subject {text!r}: an empty entry; give subjects separated by commas, e.g. '
               'virtual,eegmmidb:1,eegmmidb:2.')
        raise ExperimentError(msg)
    return _each_once(out, '--subject', repr(text), 'a subject')


def parse_seeds(text: str) -> list[int]:
    """``'0,1,2'`` -> the seeds of a sweep, whole numbers >= 0, each once."""
    bad = "{part!r} is not a whole number >= 0; give seeds separated by commas, e.g. 0,1,2."
    return _numbers(text, '--seeds', int, lambda v: v >= 0, bad, bad, 'a seed')


def parse_param(text: str) -> Param:
    """``'fsm.certainty_threshold=0.3,0.5'`` -> (node, parameter, values as given)."""
    match = _PARAM.match(text.strip())
    values = [v.strip() for v in match.group(3).split(',')] if match else []
    if not match or not all(values):
        msg = (f'--param {text!r}: give node.parameter=v1,v2,... with the node and parameter '
               'names of the profile\'s parameter files, e.g. fsm.certainty_threshold=0.3,0.5.')
        raise ExperimentError(msg)
    return match.group(1), match.group(2), values


def _typed(value: Any, like: Any, name: str) -> Any:
    """``value`` (text, as ``--param`` gives it, or already typed, as
    :attr:`Experiment.params <mindgrasp_experiments.experiment.Experiment.params>` holds it) as
    the type of the parameter's value in the parameter files."""
    if not isinstance(value, str):
        return _typed_value(value, like, name)
    try:
        if isinstance(like, bool):
            if value.lower() not in ('true', 'false'):
                raise ValueError(value)
            return value.lower() == 'true'
        if isinstance(like, int):
            return int(value)
        if isinstance(like, float):
            return float(value)
    except ValueError:
        kind = {bool: 'true or false', int: 'a whole number', float: 'a number'}[type(like)]
        msg = f'--param {name}={value}: {name} takes {kind} (it is {like!r} in its parameter file).'
        raise ExperimentError(msg) from None
    if isinstance(like, str):
        return value
    msg = f'--param {name}: only boolean, integer, double and string parameters can be swept.'
    raise ExperimentError(msg)


def _typed_value(value: Any, like: Any, name: str) -> Any:
    """A typed ``value`` checked against the parameter file's type (an int where a float is
    taken becomes that float)."""
    if isinstance(like, bool) or isinstance(value, bool):
        ok = isinstance(like, bool) and isinstance(value, bool)
    elif isinstance(like, float):
        ok = isinstance(value, (int, float))
        value = float(value) if ok else value
    else:
        ok = type(value) is type(like) and isinstance(like, (int, str))
    if not ok:
        msg = (f'--param {name}={value!r}: {name} takes a value like {like!r} (its parameter '
               f'file), not a {type(value).__name__}.')
        raise ExperimentError(msg)
    return value


def check_params(params: Sequence[Param], components: Sequence[NodeSpec]) -> list[Param]:
    """The params with values typed as their parameter files have them; raises
    :class:`ExperimentError` for an unknown node or parameter, a repeated one or a bad value."""
    nodes = {c.label: c for c in components}
    seen = set()
    out = []
    for node, name, values in params:
        full = f'{node}.{name}'
        if full in seen:
            msg = f'--param {full} is given twice; give all its values in one --param.'
            raise ExperimentError(msg)
        seen.add(full)
        if node not in nodes:
            msg = (f'--param {full}: no node {node!r} in this experiment; the nodes are '
                   f"{', '.join(sorted(nodes))}.")
            raise ExperimentError(msg)
        known = nodes[node].parameters
        if name not in known:
            msg = (f'--param {full}: {node} has no parameter {name!r} in its parameter files; '
                   f'it has {", ".join(sorted(known))}.')
            raise ExperimentError(msg)
        typed = [_typed(v, known[name], full) for v in values]
        _check_range(nodes[node], name, typed, full)
        out.append((node, name, typed))
    return out


def _check_range(component: NodeSpec, name: str, values: Sequence[Any], full: str) -> None:
    """ExperimentError for a value outside the range or choices that the node class declares
    (:attr:`NodeTraits.parameters`), before any trial runs."""
    import dataclasses

    from mindgrasp_ros.params import ParameterError, check_value

    cls = component.traits.parameters
    if cls is None or name not in {f.name for f in dataclasses.fields(cls)}:
        return
    for value in values:
        try:
            check_value(cls, name, value)
        except ParameterError as exc:
            msg = f'--param {full}: {exc}'
            raise ExperimentError(msg) from None


def combinations(params: Sequence[Param]) -> list[dict[str, Any]]:
    """Every combination of the swept values, as ``{'node.parameter': value}`` (one empty
    combination without params)."""
    names = [f'{node}.{name}' for node, name, _ in params]
    return [dict(zip(names, combo, strict=True))
            for combo in itertools.product(*(values for _, _, values in params))]


def apply_params(components: Sequence[NodeSpec], combo: Mapping[str, Any],
                 params_dir: str | Path | None = None) -> list[NodeSpec]:
    """Copies of ``components`` with the combination's typed parameters set (on top of the
    parameter file's, so they win, as ``-p`` on a ``ros2 run`` command line). With
    ``params_dir`` (where :func:`~mindgrasp_experiments.engine.lockstep_components` wrote the
    run's parameter files), each changed node's ``<node>.yaml`` there is written again with the
    values used."""
    from mindgrasp_launch import params as ros_params
    from mindgrasp_launch import rundir

    out = []
    for comp in components:
        given = {full.split('.', 1)[1]: value for full, value in combo.items()
                 if full.split('.', 1)[0] == comp.label}
        if given:
            comp = comp.with_parameters(given)
        if given and params_dir is not None:
            changed = ' '.join(f'{name}:={_text(value)}' for name, value in given.items())
            rundir.write_yaml(Path(params_dir) / f'{comp.label}.yaml',
                              ros_params.dump_parameters({'/**': dict(comp.parameters)}),
                              header=f'parameters of {comp.label} (lock-step; set with --param '
                                     f'{changed})')
        out.append(comp)
    return out


def _text(value: Any) -> str:
    """A parameter value as ``--param`` gives it (booleans lower-case, as ROS writes them)."""
    return str(value).lower() if isinstance(value, bool) else str(value)


def point_name(accuracy: float, combo: Mapping[str, Any]) -> str:
    """Directory name of a point: ``acc0.55`` or ``acc0.55_fsm.certainty_threshold-0.3`` (other
    characters than letters, digits and ``.+-_`` become ``_``: ``subject-eegmmidb_1``)."""
    return '_'.join([f'acc{accuracy:g}',
                     *(_UNSAFE.sub('_', f'{k}-{v}') for k, v in combo.items())])


def _mean_ci(values: Sequence[float]) -> tuple[float, list[float]]:
    """Mean and its Student-t 95 % interval (NaNs when fewer than 1 / 2 values)."""
    values = [v for v in values if math.isfinite(v)]
    if not values:
        return math.nan, [math.nan, math.nan]
    mean = statistics.fmean(values)
    if len(values) < 2:
        return mean, [math.nan, math.nan]
    from scipy.stats import t

    half = t.ppf(0.975, len(values) - 1) * statistics.stdev(values) / math.sqrt(len(values))
    return mean, [mean - half, mean + half]


#: figures of a point taken from :func:`~mindgrasp_experiments.summary.summarise` under its names
SUMMARY_KEYS = ('interrupted_trials', 'success_rate', 'success_ci95', 'correct_choice_rate',
                'correct_choice_ci95', 'correct_and_successful_rate',
                'correct_and_successful_ci95', 'wrong_grasp_rate', 'wrong_grasp_ci95',
                'no_grasp_rate', 'no_grasp_ci95', 'median_time_to_correct_grasp_s',
                'itr_bits_per_min', 'online_accuracy', 'online_accuracy_ci95', 'online_windows',
                'online_decision_accuracy', 'online_decision_accuracy_ci95', 'online_decisions',
                'calibration_accuracy', 'mean_duration_s', 'failures')


def point_figures(records: Sequence[TrialRecord], accuracy: float, combo: Mapping[str, Any],
                  calibration_accuracy: float | None = None) -> dict[str, Any]:
    """One row of the sweep table: the summary's rates with Wilson 95 % CIs (the three outcomes
    among them), the selection's information transfer rate, the decoder's online accuracy over
    windows and decisions beside its ``calibration_accuracy`` (the model's cross-validated
    accuracy, when known), and the mean time to grasp (s) with a Student-t interval."""
    s = summarise(records, calibration_accuracy)
    row: dict[str, Any] = {'accuracy': accuracy, **combo, 'trials': s['trials']}
    row.update({k: s[k] for k in SUMMARY_KEYS})
    row['mean_time_s'], row['mean_time_ci95'] = _mean_ci(
        [r.time_to_grasp_s for r in counted(records) if r.success])
    return row


def _pct(rate: float | None, ci: Sequence[float | None] | None = None) -> str:
    if rate is None or not math.isfinite(rate):
        return 'n/a'
    text = f'{100 * rate:.1f} %'
    if ci and ci[0] is not None and math.isfinite(ci[0]):
        text += f' ({100 * ci[0]:.0f}-{100 * ci[1]:.0f})'
    return text


def _secs(value: float | None, ci: Sequence[float | None] | None = None) -> str:
    if value is None or not math.isfinite(value):
        return 'n/a'
    text = f'{value:.1f} s'
    if ci and ci[0] is not None and math.isfinite(ci[0]):
        text += f' ({ci[0]:.1f}-{ci[1]:.1f})'
    return text


def _plots(points: Sequence[Mapping[str, Any]], varied: Sequence[str], out: Path) -> list[str]:
    """success_vs_accuracy and time_vs_accuracy (PNG and SVG), one line per combination, and
    outcomes_vs_online_accuracy."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    groups: dict[tuple, list[Mapping[str, Any]]] = {}
    for p in points:
        groups.setdefault(tuple(p.get(k) for k in varied), []).append(p)
    written = []

    def band(p: Mapping[str, Any], key: str, value: float) -> tuple[float, float]:
        ci = p.get(key) or [math.nan, math.nan]
        low = ci[0] if ci[0] is not None else math.nan
        high = ci[1] if ci[1] is not None else math.nan
        return value - low, high - value

    for stem, ylabel, series in (
            ('success_vs_accuracy', 'rate (Wilson 95 % CI)',
             (('success', 'success_rate', 'success_ci95'),
              ('correct grasp (correct and successful)', 'correct_and_successful_rate',
               'correct_and_successful_ci95'),
              ('wrong grasp', 'wrong_grasp_rate', 'wrong_grasp_ci95'))),
            ('time_vs_accuracy', 'mean time to a successful grasp (simulated s, 95 % CI)',
             (('time to grasp', 'mean_time_s', 'mean_time_ci95'),))):
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        for key, group in groups.items():
            group = sorted(group, key=lambda p: p['accuracy'])
            suffix = ', '.join(f'{k}={v}' for k, v in zip(varied, key, strict=True))
            for label, field, ci in series:
                xs = [p['accuracy'] for p in group]
                ys = [p[field] if p[field] is not None else math.nan for p in group]
                err = [band(p, ci, y) for p, y in zip(group, ys, strict=True)]
                ax.errorbar(xs, ys, yerr=list(zip(*err, strict=True)) if err else None,
                            marker='o', capsize=3,
                            label=f'{label} ({suffix})' if suffix else label)
        ax.set_xlabel('virtual subject accuracy (probability of the right class)')
        ax.set_ylabel(ylabel)
        if stem == 'success_vs_accuracy':
            ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        ax.set_title('Set locations against BCI accuracy')
        for ext in ('png', 'svg'):
            fig.savefig(out / f'{stem}.{ext}', dpi=120, bbox_inches='tight')
            written.append(f'{stem}.{ext}')
        plt.close(fig)
    written += _outcomes_vs_online_accuracy(points, plt, out)
    return written


def _outcomes_vs_online_accuracy(points: Sequence[Mapping[str, Any]], plt: Any, out: Path
                                 ) -> list[str]:
    """outcomes_vs_online_accuracy (PNG, SVG): correct and wrong grasps against the decoder's
    realised online accuracy (per window), one marker per subject, so the synthetic subject's
    points and the replay subjects' (real EEG) lie on the same axes."""
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    subjects = sorted({str(p.get('subject', 'virtual')) for p in points})
    markers = 'osD^v<>p'
    for i, subject in enumerate(subjects):
        group = [p for p in points if str(p.get('subject', 'virtual')) == subject
                 and p.get('online_accuracy') is not None]
        for field, colour, what in (('correct_and_successful_rate', 'tab:green', 'correct'),
                                    ('wrong_grasp_rate', 'tab:red', 'wrong')):
            xs = [p['online_accuracy'] for p in group]
            ys = [p[field] if p[field] is not None else math.nan for p in group]
            xerr = [[x - (p.get('online_accuracy_ci95') or [x, x])[0] for x, p in
                     zip(xs, group, strict=True)],
                    [(p.get('online_accuracy_ci95') or [x, x])[1] - x for x, p in
                     zip(xs, group, strict=True)]]
            ax.errorbar(xs, ys, xerr=xerr if xs else None, marker=markers[i % len(markers)],
                        linestyle='none', color=colour, capsize=2,
                        label=f'{what} grasp, {subject}')
    ax.set_xlabel('decoder online accuracy against the intent (per window, 95 % CI)')
    ax.set_ylabel('rate of trials')
    ax.set_ylim(-0.02, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title('Outcomes against the realised decoder accuracy')
    written = []
    for ext in ('png', 'svg'):
        fig.savefig(out / f'outcomes_vs_online_accuracy.{ext}', dpi=120, bbox_inches='tight')
        written.append(f'outcomes_vs_online_accuracy.{ext}')
    plt.close(fig)
    return written


def _report(points: Sequence[Mapping[str, Any]], varied: Sequence[str],
            run: Mapping[str, Any], plots: Sequence[str]) -> str:
    seed, subject = str(run.get('seed')), str(run.get('subject', 'virtual'))
    lines = [f"# Accuracy sweep: set locations, {len(points)} points", '',
             f"Command: `{run.get('command', '')}`. {'Seeds' if ',' in seed else 'Seed'} {seed}; "
             f"{run.get('trials')} trials per point; {'subjects' if ',' in subject else 'subject'}"
             f" {subject}.", '',
             'Rates with their Wilson 95 % CIs in brackets (%); the time to grasp over '
             'successful trials, with a Student-t 95 % CI. Outcomes: correct grasp (the desired '
             'object lifted), wrong grasp (another object lifted, or a grasp closed on one), no '
             'grasp. ITR: the selection\'s information transfer rate (Wolpaw). Online accuracy: '
             'the decoder\'s predictions against the subject\'s intent, per classifier window '
             'and per decision (the most frequent class over one held intent), beside the '
             'model\'s cross-validated calibration accuracy.', '',
             '| accuracy | ' + ''.join(f'{k} | ' for k in varied) + 'trials | success | '
             'correct choice | correct grasp (correct and successful) | wrong grasp | no grasp | '
             'time to grasp | median time to a correct grasp | ITR | online accuracy '
             '(windows) | online accuracy (decisions) | calibration accuracy |',
             '|---|' + '---|' * len(varied) + '---|' * 12]
    for p in points:
        itr = p.get('itr_bits_per_min')
        itr_text = 'n/a' if itr is None or not math.isfinite(itr) else f'{itr:.2f} bits/min'
        lines.append(
            f"| {p['accuracy']:g} | " + ''.join(f'{p.get(k)} | ' for k in varied)
            + f"{p['trials']} | {_pct(p['success_rate'], p['success_ci95'])} | "
            f"{_pct(p['correct_choice_rate'], p['correct_choice_ci95'])} | "
            f"{_pct(p['correct_and_successful_rate'], p['correct_and_successful_ci95'])} | "
            f"{_pct(p['wrong_grasp_rate'], p['wrong_grasp_ci95'])} | "
            f"{_pct(p['no_grasp_rate'], p['no_grasp_ci95'])} | "
            f"{_secs(p['mean_time_s'], p['mean_time_ci95'])} | "
            f"{_secs(p['median_time_to_correct_grasp_s'])} | {itr_text} | "
            f"{_pct(p['online_accuracy'], p['online_accuracy_ci95'])} of "
            f"{p['online_windows']} | "
            f"{_pct(p['online_decision_accuracy'], p['online_decision_accuracy_ci95'])} of "
            f"{p['online_decisions']} | {_pct(p['calibration_accuracy'])} |")
    interrupted = sum(p.get('interrupted_trials') or 0 for p in points)
    if interrupted:
        lines += ['', f'{interrupted} interrupted trial(s) (Ctrl-C) are left out of the figures.']
    lines += ['', 'Plots: ' + ', '.join(f'[{p}]({p})' for p in plots), '',
              'Each point\'s records, summary and report: '
              + ', '.join(f"[{p['point']}](points/{p['point']}/report.md)" for p in points), '']
    if 'wall_s' in run:
        lines += [f"Ran in {run['wall_s']:.0f} s of wall time ({run['sim_s']:.0f} simulated s, "
                  f"{run.get('workers', 1)} worker(s)).", '']
    return '\n'.join(lines)


def write_sweep(out: str | Path, points: Sequence[Mapping[str, Any]], varied: Sequence[str],
                run: Mapping[str, Any]) -> dict[str, Any]:
    """Write sweep.csv, sweep.json, the plots and report.md into ``out``; returns the sweep
    document (``points``: one row per accuracy and combination)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    points = [dict(p) for p in points]
    columns = ['point', 'accuracy', *varied, 'trials', 'interrupted_trials', 'success_rate',
               'success_ci95', 'correct_choice_rate', 'correct_choice_ci95',
               'correct_and_successful_rate', 'correct_and_successful_ci95', 'wrong_grasp_rate',
               'wrong_grasp_ci95', 'no_grasp_rate', 'no_grasp_ci95', 'mean_time_s',
               'mean_time_ci95', 'median_time_to_correct_grasp_s', 'itr_bits_per_min',
               'online_accuracy', 'online_accuracy_ci95', 'online_windows',
               'online_decision_accuracy', 'online_decision_accuracy_ci95', 'online_decisions',
               'calibration_accuracy']
    with (out / 'sweep.csv').open('w', newline='', encoding='utf-8') as f:
        writer = csv.writer(f, lineterminator='\n')
        writer.writerow([c.replace('_ci95', '_ci95_low') for c in columns]
                        + [c.replace('_ci95', '_ci95_high') for c in columns if 'ci95' in c])
        for p in points:
            values = [p.get(c)[0] if 'ci95' in c else p.get(c) for c in columns]
            values += [p.get(c)[1] for c in columns if 'ci95' in c]
            writer.writerow(['' if isinstance(v, float) and not math.isfinite(v) else v
                             for v in values])
    plots = _plots(points, varied, out)
    doc = finite({'points': points, 'varied': list(varied), 'run': dict(run), 'plots': plots})
    (out / 'sweep.json').write_text(json.dumps(doc, indent=2) + '\n', encoding='utf-8')
    (out / 'report.md').write_text(_report(points, varied, run, plots), encoding='utf-8')
    return doc
