"""Run the random-locations grasp experiment (autonomous, one object per trial, lock-step sim).

Each trial places one object (random shape and colour) 0.2-0.7 m from the base; the controller
turns left until it sees it, centres it, approaches and grasps it without BCI input, as in the
MIndGrasp paper. Prints success per shape and overall and the mean and median time to grasp;
``--json`` adds one JSON object as the last line. ``--realism default`` (or a profile YAML) runs
the trials with sensor noise and physical spread (mindgrasp_sim.realism), seeded by ``--seed``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from mindgrasp_common.cli_checks import non_negative_int, positive_float, positive_int


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``mindgrasp experiment random-locations``."""
    parser.add_argument('--trials', type=positive_int, default=90,
                        help='number of trials (default 90)')
    parser.add_argument('--seed', type=non_negative_int, default=0,
                        help='seed of the placements (default 0)')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON object with the figures as the last line')
    parser.add_argument('--params-file', default=None,
                        help='controller parameters (ROS YAML, default: mindgrasp_fsm '
                             'param/fsm.yaml)')
    parser.add_argument('--timeout', type=positive_float, default=120.0,
                        help='simulated seconds per trial before it counts as failed (default 120)')
    parser.add_argument('--shape-model', default=None,
                        help="depth shape CNN (default the vision default; 'none' to disable)")
    parser.add_argument('--realism', default='none',
                        help='sensor noise and physical spread: none (default), default or a '
                             'profile YAML path (mindgrasp_sim.realism)')
    parser.add_argument('--quiet', action='store_true', help='no line per trial')


def _fmt_rate(value: float) -> str:
    return 'n/a' if math.isnan(value) else f'{100 * value:5.1f} %'


def _finite(value: object) -> object:
    """NaN -> None, so the JSON line is strict JSON."""
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value


def main(args: argparse.Namespace) -> int:
    """Run the trials and print the figures; 0 on success, 2 on bad arguments."""
    from mindgrasp_fsm.errors import FsmError
    from mindgrasp_fsm.experiment import run_random_locations
    from mindgrasp_fsm.params import FsmParams, default_params_path

    if args.trials < 1:
        print(f'mindgrasp experiment random-locations: --trials must be >= 1, got {args.trials}.',
              file=sys.stderr)
        return 2
    if args.timeout <= 0:
        print(f'mindgrasp experiment random-locations: --timeout must be > 0 s, got '
              f'{args.timeout}.', file=sys.stderr)
        return 2
    try:
        params = FsmParams.from_yaml(args.params_file or default_params_path())
    except FsmError as exc:
        print(f'mindgrasp experiment random-locations: {exc}', file=sys.stderr)
        return 2
    from mindgrasp_sim.errors import SimError
    from mindgrasp_sim.realism import RealismProfile

    try:
        realism = RealismProfile.load(args.realism)
    except SimError as exc:
        print(f'mindgrasp experiment random-locations: --realism: {exc}', file=sys.stderr)
        return 2

    def progress(rec: object) -> None:
        if args.quiet:
            return
        t = f'{rec.time_to_grasp:6.1f} s' if rec.success else '     - '
        print(f'trial {rec.index + 1:3d}/{args.trials}: {rec.colour:6s} {rec.shape:8s} '
              f'r {rec.radius:.2f} m, {rec.angle_deg:+6.1f} deg: '
              f'{"grasped" if rec.success else "FAILED "} {t} '
              f'({rec.attempts} attempt(s); {rec.reason})', flush=True)

    summary = run_random_locations(args.trials, args.seed, params, timeout=args.timeout,
                                   shape_model=args.shape_model, progress=progress,
                                   realism=realism)
    print(f'Random locations: {summary["trials"]} trials, seed {args.seed}, shape model '
          f'{summary["shape_model"]}, realism {summary["realism"]}')
    for shape, rate in summary['success_by_shape'].items():
        c = summary['counts_by_shape'][shape]
        print(f'  {shape:8s} {_fmt_rate(rate)}  ({c["successes"]}/{c["trials"]})')
    print(f'  overall  {_fmt_rate(summary["success_rate"])}  '
          f'({summary["successes"]}/{summary["trials"]})')
    print(f'Time to grasp: mean {summary["mean_time_s"]:.1f} s, median '
          f'{summary["median_time_s"]:.1f} s (simulated)')
    print(f'Simulated {summary["sim_time_s"]:.0f} s in {summary["wall_time_s"]:.0f} s wall time '
          f'(real-time factor {summary["real_time_factor"]:.1f}); vision '
          f'{summary["vision_ms_per_frame"]:.2f} ms per frame')
    if args.json:
        print(json.dumps(_finite(summary)))
    return 0
