"""``mindgrasp experiment set-locations | random-locations``: the paper's protocols in lock-step.

The experiment launch profile's own nodes (simulator, virtual amplifier, classifier, vision,
controller, trial manager) are composed in one process on simulated time, one fresh graph per
trial seeded from ``(seed, trial)``; ``--workers N`` runs trials in N processes with the same
records. The run directory (``--out``, default ``runs/<UTC>_<protocol>/``) gets records.csv,
records.parquet, summary.json, report.md and the plots; ``--json`` prints one JSON object as the
last line. Ctrl-C writes the records and report of the trials done so far.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mindgrasp_experiments.experiment import Experiment

PROTOCOL_SUBJECTS = {'set_locations': ('noise', 'virtual', 'oracle'),
                     'random_locations': ('autonomous',)}
#: the most trials one command runs (a paper protocol has 90): a larger count could never
#: finish, and 99999999999999999999 ended in numpy's OverflowError
MAX_TRIALS = 100_000


def subject_type(text: str) -> str:
    """argparse type of --subject: noise, virtual, oracle, eegmmidb:<subject>, a subject file
    (``*.yaml``) or ``virtual:FILE.yaml`` (files checked when the experiment starts)."""
    import argparse

    from mindgrasp_experiments.fitted_subject import is_fitted
    from mindgrasp_experiments.subjects import is_replay

    if text in ('noise', 'virtual', 'oracle') or is_replay(text) or is_fitted(text):
        return text
    msg = (f'unknown subject {text!r}; use noise, virtual, oracle, eegmmidb:<subject> (real '
           'EEG of an EEGMMIDB subject, e.g. eegmmidb:1), a replay subject file (.yaml) or '
           'virtual:FILE.yaml (a head fitted by mindgrasp eeg fit-virtual)')
    raise argparse.ArgumentTypeError(msg)


def add_common_arguments(parser: argparse.ArgumentParser, trials: int,
                         trial_timeout: float = 600.0) -> None:
    """Options of every ``mindgrasp experiment`` protocol (numbers checked by argparse)."""
    from mindgrasp_common.cli_checks import bounded_int, non_negative_int, positive_float
    from mindgrasp_common.robot_description import robot_choices

    parser.add_argument('--trials', type=bounded_int(1, MAX_TRIALS), default=trials,
                        help=f'number of trials, 1-{MAX_TRIALS} (default {trials})')
    parser.add_argument('--seed', type=non_negative_int, default=0,
                        help='seed of the trial draws, the EEG and the subject (default 0)')
    parser.add_argument('--workers', type=bounded_int(1, 256), default=1,
                        help='worker processes; the same seed gives the same records whatever '
                             'the number (default 1)')
    parser.add_argument('--out', metavar='DIR', default=None,
                        help='run directory (default runs/<UTC time>_<protocol>/)')
    parser.add_argument('--launch', metavar='FILE', default=None,
                        help='a launch file whose nodes replace the experiment\'s nodes of the '
                             'same name (e.g. your own controller named fsm) or are added')
    parser.add_argument('--json', action='store_true',
                        help='print one JSON object with the figures as the last line')
    parser.add_argument('--step', type=positive_float, default=0.02, metavar='S',
                        help='lock-step clock step in simulated s (default 0.02)')
    parser.add_argument('--stall-timeout', type=positive_float, default=120.0, metavar='S',
                        help='abort a trial after S simulated s without a controller state '
                             'change (default 120)')
    parser.add_argument('--trial-timeout', type=positive_float, default=trial_timeout,
                        metavar='S', help='end a trial without a grasp after S simulated s '
                                          f'(default {trial_timeout:g})')
    parser.add_argument('--no-progress', action='store_true', help='no progress bar')
    parser.add_argument('--ray', metavar='ADDRESS', default=None,
                        help='run the trials as Ray tasks (pip install -e ".[cluster]"): auto '
                             '(a local Ray instance of this run) or '
                             'HOST:PORT of a cluster\'s head node; same records as --workers')
    parser.add_argument('--robot', default='mindgrasp_arm', metavar='NAME|YAML',
                        help=f'the arm (default mindgrasp_arm): {robot_choices()} '
                             '(mindgrasp_common.robot_description)')
    parser.add_argument('--realism', default='none',
                        help='sensor noise and physical spread: none (default), default or a '
                             'profile YAML path (mindgrasp_sim.realism), seeded per trial')


def fail(command: str, text: str) -> int:
    """One clear line on stderr, exit code 2."""
    print(f'mindgrasp experiment {command}: {text}', file=sys.stderr)
    return 2


def check(args: argparse.Namespace, command: str) -> str | None:
    """The problem with the arguments, in one sentence, or None."""
    if args.trials < 1:
        return f'--trials must be a whole number >= 1, got {args.trials}.'
    if args.seed < 0:
        return f'--seed must be >= 0, got {args.seed}.'
    if args.workers < 1:
        return f'--workers must be >= 1, got {args.workers}.'
    accuracy = getattr(args, 'accuracy', None)
    if accuracy is not None and not (0.0 <= accuracy <= 1.0):
        return f'--accuracy must be within 0..1 (a probability), got {accuracy}.'
    if not (0 < args.step <= 0.1):
        return f'--step must be within (0, 0.1] simulated seconds, got {args.step}.'
    if args.stall_timeout <= 0:
        return f'--stall-timeout must be > 0 s, got {args.stall_timeout}.'
    if args.trial_timeout <= 0:
        return f'--trial-timeout must be > 0 s, got {args.trial_timeout}.'
    if args.launch is not None and not Path(args.launch).is_file():
        return f'--launch {args.launch}: no such launch file; give a *.launch.py path.'
    if getattr(args, 'ray', None) is not None:
        from mindgrasp_experiments import ExperimentError
        from mindgrasp_experiments.workers import check_ray_address

        try:
            check_ray_address(args.ray)
        except ExperimentError as exc:
            return str(exc)
    if getattr(args, 'robot', None) is not None:
        from mindgrasp_common.robot_description import RobotDescriptionError, load_robot

        try:
            load_robot(args.robot)
        except RobotDescriptionError as exc:
            return f'--robot: {exc}'
    realism = getattr(args, 'realism', None)
    if realism is not None:
        from mindgrasp_sim.errors import SimError
        from mindgrasp_sim.realism import RealismProfile

        try:
            RealismProfile.load(realism)
        except SimError as exc:
            return f'--realism: {exc}'
    return None


def add_param_argument(parser: argparse.ArgumentParser) -> None:
    """``--param NODE.PARAM=V`` of an experiment: one value sets a node's parameter for every
    trial; several values compare them, each as a point of a sweep."""
    parser.add_argument('--param', action='append', default=[], metavar='NODE.PARAM=V1,V2,...',
                        help='set a parameter of a node (names as in the profile\'s parameter '
                             'files), e.g. fsm.paradigm=paper; several values, e.g. '
                             'fsm.paradigm=paper,scan, run each as a point of a sweep '
                             '(mindgrasp experiment sweep) and compare them; repeat for more')


def experiment_from(args: argparse.Namespace, protocol: str,
                    params: dict[str, Any] | None = None) -> Experiment:
    """The :class:`~mindgrasp_experiments.experiment.Experiment` the options describe."""
    from mindgrasp_experiments.experiment import Experiment

    return Experiment(protocol, subject=getattr(args, 'subject', 'autonomous'),
                      trials=args.trials, seed=args.seed, workers=args.workers,
                      accuracy=getattr(args, 'accuracy', None), params=params or {},
                      robot=getattr(args, 'robot', None), realism=getattr(args, 'realism', None),
                      launch=args.launch, step_s=args.step, trial_timeout_s=args.trial_timeout,
                      stall_timeout_s=args.stall_timeout, ray=args.ray)


def run_experiment(args: argparse.Namespace, protocol: str, command: str, *,
                   compare: Callable[[argparse.Namespace, str], int] | None = None) -> int:
    """Run the protocol with ``args``; write the run directory; print the figures.

    ``compare(args, command)`` runs a ``--param`` given several values (the sweep verb's
    :func:`~mindgrasp_experiments.commands.experiment_sweep.compare`); without it several values are
    refused.
    """
    from tqdm import tqdm

    from mindgrasp_experiments import ExperimentError
    from mindgrasp_experiments.sweep import parse_param

    problem = check(args, command)
    if problem:
        return fail(command, problem)
    try:
        params = [parse_param(p) for p in getattr(args, 'param', [])]
    except ExperimentError as exc:
        return fail(command, str(exc))
    if any(len(values) > 1 for _node, _name, values in params):
        if compare is None:
            return fail(command, '--param takes one value per parameter here.')
        return compare(args, command)
    experiment = experiment_from(args, protocol, {f'{node}.{name}': values[0]
                                                  for node, name, values in params})
    bars: list[tqdm] = []     # made once the graph is checked: an error stays one line
    started: list[float] = []

    def start() -> None:
        started.append(time.perf_counter())
        bars.append(tqdm(total=args.trials, unit='trial', disable=args.no_progress,
                         file=sys.stderr, desc=f'{protocol} ({experiment.subject})',
                         dynamic_ncols=True))

    def progress(runs: list) -> None:
        done = [r.record for r in runs]
        bars[0].update(1)
        bars[0].set_postfix(
            success=f'{sum(r.success for r in done)}/{len(done)}',
            rtf=f'{sum(r.sim_s for r in runs) / (time.perf_counter() - started[0]):.1f}')

    def warn(line: str) -> None:
        text = f'mindgrasp experiment {command}: {line}'
        if bars:
            bars[0].write(text, file=sys.stderr)
        else:
            print(text, file=sys.stderr)

    log: list[str] | None = [] if args.json else None
    try:
        results = experiment.run(
            args.out, command=' '.join(['mindgrasp', 'experiment', command, *sys.argv[3:]]),
            log=log.append if log is not None else print, on_start=start, on_trial=progress,
            warn=warn)
    except ExperimentError as exc:
        return fail(command, str(exc))
    finally:
        for bar in bars:
            bar.close()
    s, info, out = results.summary, results.info, results.run_dir
    cut = (f" (and {s['interrupted_trials']} interrupted, left out)"
           if s['interrupted_trials'] else '')
    print(f"{protocol.replace('_', ' ').capitalize()}, subject {experiment.subject}: "
          f"{s['trials']} trials{cut} in {out}")
    print(f"  correct grasp {_pct(s['correct_and_successful_rate'])}, wrong grasp "
          f"{_pct(s['wrong_grasp_rate'])}, no grasp {_pct(s['no_grasp_rate'])}; grasp success "
          f"{_pct(s['success_rate'])}, correct choice {_pct(s['correct_choice_rate'])}")
    print(f"  mean trial {_secs(s['mean_duration_s'])}, median time to a correct grasp "
          f"{_secs(s['median_time_to_correct_grasp_s'])}; information transfer rate "
          f"{_bits(s['itr_bits_per_min'])}")
    if s['online_windows'] or math.isfinite(s['calibration_accuracy']):
        print(f"  decoder online accuracy {_pct(s['online_accuracy'])} of "
              f"{s['online_windows']} windows (calibration {_pct(s['calibration_accuracy'])})")
    if s.get('answer_pair'):
        gate = (f"; calibration gate {s['gate_verdict']}, predicted "
                f"{_pct(s['predicted_correct_rate'])} correct, "
                f"{_pct(s['predicted_wrong_rate'])} wrong" if s.get('gate_verdict') else '')
        print(f"  answer pair {s['answer_pair']}{gate}")
    print(f"  simulated {info['sim_s']:.0f} s in {info['wall_s']:.0f} s wall: real-time factor "
          f"{info['real_time_factor']:.1f}, {info['cpu_s_per_sim_s']:.3f} CPU s per simulated s")
    print(f"  report: {out / 'report.md'}")
    if args.json:
        print(json.dumps(results.figures()))
    return 130 if results.interrupted else 1 if results.unwritten else 0


def _pct(rate: float) -> str:
    return 'n/a' if not math.isfinite(rate) else f'{100 * rate:.1f} %'


def _secs(value: float) -> str:
    return 'n/a' if not math.isfinite(value) else f'{value:.1f} s'


def _bits(value: float) -> str:
    return 'n/a' if not math.isfinite(value) else f'{value:.2f} bits/min'
