"""Plots of an experiment's records (matplotlib, Agg), each written as PNG and SVG.

- ``set_location_map``: each object's place around the base, with attempted (desired) and
  successful grasps.
- ``random_location_scatter``: successes and failures by shape at their places.
- ``time_to_grasp``: histogram of the simulated time to a successful grasp.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from mindgrasp_experiments.records import TrialRecord, shape_of

__all__ = ['write_plots']

_MARKERS = {'cube': 's', 'cylinder': 'o', 'sphere': '^'}
_COLOURS = {'red': 'tab:red', 'yellow': 'gold', 'blue': 'tab:blue'}


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


def write_plots(records: Sequence[TrialRecord], run_dir: str | Path,
                protocol: str = '') -> list[Path]:
    """Write the plots that fit ``protocol``; returns the files written."""
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    run_dir = Path(run_dir)
    out: list[Path] = []
    placed = [r for r in records if math.isfinite(r.desired_x) and math.isfinite(r.desired_y)]
    if protocol == 'set_locations' and records:
        fig, ax = plt.subplots(figsize=(6.5, 6.5))
        places = _set_location_places()
        for r in placed:
            places.setdefault(r.desired, (r.desired_x, r.desired_y))
        for label, (x, y) in places.items():
            asked = sum(r.desired == label for r in records)
            gone_for = sum((r.grasped or r.chosen) == label for r in records)
            lifted = sum(r.success and r.grasped == label for r in records)
            right = sum(r.correct_and_successful and r.desired == label for r in records)
            colour, _, shape = label.partition(' ')
            ax.scatter(x, y, s=90 + 60 * gone_for, marker=_MARKERS.get(shape, 'o'),
                       c=_COLOURS.get(colour, 'grey'), edgecolors='k', alpha=0.85)
            ax.annotate(f'{label}\nasked {asked}, attempted {gone_for}\nlifted {lifted}, '
                        f'correct {right}', (x, y), fontsize=7, textcoords='offset points',
                        xytext=(9, 5))
        _base(ax)
        ax.margins(0.18)
        ax.set_title('Set locations: per object, trials asking for it, grasps attempted on it\n'
                     '(marker size), lifts, and correct successful grasps')
        out += _save(fig, run_dir, 'set_location_map')
        plt.close(fig)
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
    times = [r.time_to_grasp_s for r in records if r.success and math.isfinite(r.time_to_grasp_s)]
    fig, ax = plt.subplots(figsize=(6, 4))
    if times:
        ax.hist(times, bins=min(30, max(5, len(times) // 3)), color='tab:blue', alpha=0.8)
    ax.set_xlabel('time to a successful grasp (simulated s)')
    ax.set_ylabel('trials')
    ax.set_title(f'Time to grasp ({len(times)} successful trials of {len(records)})')
    out += _save(fig, run_dir, 'time_to_grasp')
    plt.close(fig)
    return out
