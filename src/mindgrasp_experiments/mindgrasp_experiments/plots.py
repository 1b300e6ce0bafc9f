"""Plots of an experiment's records (matplotlib, Agg), each written as PNG and SVG.

- ``set_location_map``: each object's place around the base with the outcomes of the trials
  that asked for it (correct grasp, wrong grasp, no grasp: separate markers, sized by count) and
  arrows from the desired object to the one grasped instead.
- ``random_location_scatter``: successes and failures by shape at their places.
- ``time_to_grasp``: histogram of the simulated time to a successful grasp, correct and wrong
  grasps stacked apart.

A population run (:mod:`~mindgrasp_experiments.population`) adds, from its per-subject table
(:func:`write_population_plots`):

- ``population_outcomes``: per subject, correct, wrong and no grasps as stacked bars (share of
  its trials), the subject's answer pair and gate verdict under its name;
- ``predicted_vs_measured``: each subject's correct rate as the calibration predicted it
  against the measured one, with the identity line and the band of +/- 20 points.

Interrupted trials are left out, as from the figures (:func:`~.summary.counted`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from mindgrasp_experiments.records import TrialRecord, shape_of
from mindgrasp_experiments.summary import counted

__all__ = ['write_plots', 'write_population_plots']

_MARKERS = {'cube': 's', 'cylinder': 'o', 'sphere': '^'}
_COLOURS = {'red': 'tab:red', 'yellow': 'gold', 'blue': 'tab:blue'}
#: how each outcome is drawn on the set-location map (scatter keywords) and named in its legend
_OUTCOME_STYLE = {
    'correct_grasp': ('correct grasp', {'marker': 'o', 'c': 'tab:green', 'edgecolors': 'k'}),
    'wrong_grasp': ('wrong grasp', {'marker': 'X', 'c': 'tab:red', 'edgecolors': 'k'}),
    'no_grasp': ('no grasp', {'marker': 'o', 'facecolors': 'none', 'edgecolors': 'tab:grey'}),
}


def _save(fig, run_dir: Path, stem: str) -> list[Path]:
    out = []
    for ext in ('png', 'svg'):
        path = run_dir / f'{stem}.{ext}'
        fig.savefig(path, dpi=120, bbox_inches='tight')
        out.append(path)
    return out


def _base(ax) -> None:
    ax.plot(0, 0, 'k+', ms=12)
    ax.annotate('arm base', (0, 0), textcoords='offset points', xytext=(6, -12), fontsize=8)
    ax.set_aspect('equal')
    ax.set_xlabel('x (m)')
    ax.set_ylabel('y (m)')
    ax.grid(alpha=0.3)


def _set_location_places() -> dict[str, tuple[float, float]]:
    """Label -> (x, y) of the 9 objects of the set-locations scene (m), as the simulator places
    them; empty when the scene cannot be read."""
    try:
        from mindgrasp_sim.scene import load_scene

        return {o.label: (float(o.position[0]), float(o.position[1]))
                for o in load_scene('set_locations').objects}
    except Exception:      # the plot then shows the places recorded in the trials only
        return {}


def _set_location_map(plt, records: Sequence[TrialRecord], placed: Sequence[TrialRecord],
                      run_dir: Path) -> list[Path]:
    """Each object of the scene with the outcomes of the trials that asked for it, just outside
    its place (marker size: trials), and an arrow to each object grasped instead of it."""
    from matplotlib.lines import Line2D

    fig, ax = plt.subplots(figsize=(7, 7))
    places = _set_location_places()
    for r in placed:
        places.setdefault(r.desired, (r.desired_x, r.desired_y))
    wrong: dict[tuple[str, str], int] = {}     # (desired, grasped instead) -> trials
    for r in records:
        instead = r.grasped or r.chosen
        if r.outcome == 'wrong_grasp' and instead in places and r.desired in places:
            wrong[(r.desired, instead)] = wrong.get((r.desired, instead), 0) + 1
    for (desired, instead), n in wrong.items():
        ax.annotate('', xy=places[instead], xytext=places[desired], zorder=1,
                    arrowprops={'arrowstyle': '-|>', 'color': 'tab:red', 'alpha': 0.45,
                                'lw': 0.8 + 0.6 * n, 'shrinkA': 12, 'shrinkB': 12,
                                'connectionstyle': 'arc3,rad=0.15'})
    for label, (x, y) in places.items():
        asked = [r for r in records if r.desired == label]
        colour, _, shape = label.partition(' ')
        ax.scatter(x, y, s=170, marker=_MARKERS.get(shape, 'o'), c=_COLOURS.get(colour, 'grey'),
                   edgecolors='k', alpha=0.85, zorder=2)
        # the outcomes side by side just outside the object (away from the base), each count
        # further out; the object's name inside, towards the base
        norm = math.hypot(x, y) or 1.0
        ux, uy = x / norm, y / norm
        counts = {o: sum(r.outcome == o for r in asked) for o in _OUTCOME_STYLE}
        for i, (outcome, (_name, style)) in enumerate(_OUTCOME_STYLE.items()):
            if not counts[outcome]:
                continue
            along = (i - 1) * 0.075
            ox, oy = x + 0.11 * ux - along * uy, y + 0.11 * uy + along * ux
            ax.scatter(ox, oy, s=25 + 30 * counts[outcome], zorder=3, **style)
            ax.annotate(str(counts[outcome]), (ox + 0.065 * ux, oy + 0.065 * uy), fontsize=7,
                        ha='center', va='center', zorder=4)
        ax.annotate(f'{label}\nasked {len(asked)}', (x - 0.13 * ux, y - 0.13 * uy), fontsize=7,
                    ha='center', va='center')
    _base(ax)
    ax.margins(0.25)
    handles = [Line2D([], [], linestyle='none', markersize=8,
                      markerfacecolor=style.get('c', style.get('facecolors')),
                      markeredgecolor=style['edgecolors'], marker=style['marker'],
                      label=f'{name} ({sum(r.outcome == o for r in records)})')
               for o, (name, style) in _OUTCOME_STYLE.items()]
    handles.append(Line2D([], [], color='tab:red', alpha=0.45, lw=1.4,
                          label='grasped instead of the desired object'))
    ax.legend(handles=handles, fontsize=7, loc='upper left', bbox_to_anchor=(1.01, 1.0))
    ax.set_title('Set locations: outcomes of the trials asking for each object\n'
                 '(marker size and number: trials)')
    paths = _save(fig, run_dir, 'set_location_map')
    plt.close(fig)
    return paths


def write_plots(records: Sequence[TrialRecord], run_dir: str | Path,
                protocol: str = '') -> list[Path]:
    """Write the plots that fit ``protocol``; returns the files written."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    run_dir = Path(run_dir)
    out: list[Path] = []
    records = counted(records)
    placed = [r for r in records if math.isfinite(r.desired_x) and math.isfinite(r.desired_y)]
    if protocol == 'set_locations' and records:
        out += _set_location_map(plt, records, placed, run_dir)
    if protocol == 'random_locations' and placed:
        fig, ax = plt.subplots(figsize=(6, 6))
        for shape, marker in _MARKERS.items():
            for ok, face in ((True, 'tab:green'), (False, 'none')):
                rs = [r for r in placed if shape_of(r.desired) == shape and r.success == ok]
                if rs:
                    ax.scatter([r.desired_x for r in rs], [r.desired_y for r in rs],
                               marker=marker, facecolors=face, edgecolors='tab:green' if ok
                               else 'tab:red', label=f"{shape} {'success' if ok else 'failure'}"
                               f' ({len(rs)})')
        _base(ax)
        ax.legend(fontsize=7, loc='upper right')
        ax.set_title('Random locations: successes and failures by shape')
        out += _save(fig, run_dir, 'random_location_scatter')
        plt.close(fig)
    kinds = [(label, colour, [r.time_to_grasp_s for r in records
                              if r.success and r.outcome == outcome
                              and math.isfinite(r.time_to_grasp_s)])
             for outcome, label, colour in (('correct_grasp', 'correct grasp', 'tab:green'),
                                            ('wrong_grasp', 'wrong grasp', 'tab:red'))]
    n_times = sum(len(times) for _, _, times in kinds)
    fig, ax = plt.subplots(figsize=(6, 4))
    if n_times:
        ax.hist([times for _, _, times in kinds], bins=min(30, max(5, n_times // 3)),
                stacked=True, color=[c for _, c, _ in kinds], alpha=0.8,
                label=[f'{label} ({len(times)})' for label, _, times in kinds])
        ax.legend(fontsize=8)
    ax.set_xlabel('time to a successful grasp (simulated s)')
    ax.set_ylabel('trials')
    ax.set_title(f'Time to grasp ({n_times} successful trials of {len(records)})')
    out += _save(fig, run_dir, 'time_to_grasp')
    plt.close(fig)
    return out


def _population_outcomes(plt, rows: Sequence[dict], out: Path) -> list[Path]:
    """Stacked bars: each subject's correct, wrong and no grasps as shares of its trials."""
    ran = [r for r in rows if r.get('trials')]
    fig, ax = plt.subplots(figsize=(max(5.0, 0.6 * len(rows) + 2.0), 4.5))
    x = list(range(len(rows)))
    bottom = [0.0] * len(rows)
    for outcome, key, colour in (('correct grasp', 'correct', 'tab:green'),
                                 ('wrong grasp', 'wrong_grasp', 'tab:red'),
                                 ('no grasp', 'no_grasp', 'lightgrey')):
        shares = [(r.get(f'{key}_count') or 0) / r['trials'] if r.get('trials') else 0.0
                  for r in rows]
        total = sum(r.get(f'{key}_count') or 0 for r in ran)
        ax.bar(x, shares, bottom=bottom, color=colour, edgecolor='k', linewidth=0.4,
               label=f'{outcome} ({total})')
        bottom = [b + s for b, s in zip(bottom, shares, strict=True)]
    for i, r in enumerate(rows):
        if not r.get('trials'):
            ax.annotate('not run', (i, 0.02), rotation=90, ha='center', va='bottom', fontsize=7)
    ax.axhline(0.5, color='k', lw=0.8, ls=':')
    ax.set_xticks(x)
    ax.set_xticklabels([f"{r['label']}\n{r.get('answer_pair') or '-'}\n"
                        f"{r.get('gate_verdict') or '-'}" for r in rows], fontsize=7,
                       rotation=0 if len(rows) <= 8 else 60)
    ax.set_ylim(0, 1)
    ax.set_ylabel('share of the subject\'s trials')
    ax.set_xlabel('subject (answer pair, gate verdict)')
    ax.legend(fontsize=8, loc='upper left', bbox_to_anchor=(1.01, 1.0))
    trials = sorted({r['trials'] for r in ran})
    ax.set_title(f"Outcomes per subject ({', '.join(map(str, trials)) or 0} trials each, "
                 'set locations)')
    paths = _save(fig, out, 'population_outcomes')
    plt.close(fig)
    return paths


def _predicted_vs_measured(plt, rows: Sequence[dict], out: Path) -> list[Path]:
    """Predicted against measured correct rate, identity line and the +/- 20-point band."""
    fig, ax = plt.subplots(figsize=(5.5, 5.5))
    ax.plot([0, 1], [0, 1], color='k', lw=1, label='identity')
    ax.fill_between([0, 1], [-0.2, 0.8], [0.2, 1.2], color='tab:blue', alpha=0.12,
                    label='within 20 points')
    colours = {'ready': 'tab:green', 'needs_training': 'tab:orange', 'not_ready': 'tab:red'}
    shown = [r for r in rows if r.get('predicted_correct_rate') is not None
             and r.get('correct_rate') is not None]
    for verdict in dict.fromkeys(str(r.get('gate_verdict') or '-') for r in shown):
        rs = [r for r in shown if str(r.get('gate_verdict') or '-') == verdict]
        ax.scatter([r['predicted_correct_rate'] for r in rs], [r['correct_rate'] for r in rs],
                   c=colours.get(verdict, 'tab:grey'), edgecolors='k', zorder=3,
                   label=f'gate: {verdict} ({len(rs)})')
        for r in rs:
            ax.annotate(r['label'], (r['predicted_correct_rate'], r['correct_rate']),
                        textcoords='offset points', xytext=(4, 3), fontsize=6)
    if not shown:
        ax.text(0.5, 0.5, 'no subject has a predicted correct rate\n(the calibration wrote '
                'no gate prediction)', ha='center', va='center', fontsize=9)
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect('equal')
    ax.grid(alpha=0.3)
    ax.set_xlabel('predicted correct rate (calibration gate)')
    ax.set_ylabel('measured correct rate (closed loop)')
    ax.legend(fontsize=7, loc='lower right')
    ax.set_title(f'Predicted against measured ({len(shown)} subjects)')
    paths = _save(fig, out, 'predicted_vs_measured')
    plt.close(fig)
    return paths


def write_population_plots(rows: Sequence[dict], out: str | Path) -> list[Path]:
    """population_outcomes and predicted_vs_measured (PNG and SVG) of a population's
    per-subject rows (:func:`~mindgrasp_experiments.population.subject_row`); returns the
    files written."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    out = Path(out)
    return [*_population_outcomes(plt, rows, out), *_predicted_vs_measured(plt, rows, out)]
