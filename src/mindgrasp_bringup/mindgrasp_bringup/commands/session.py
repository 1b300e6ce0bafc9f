"""Run a calibration session: the phases of a plan, retraining between them, one subject folder.

    mindgrasp session run --subject S01 --plan graded            # virtual subject, headless
    mindgrasp session run --subject S01 --amp lsl --eeg-stream MyAmp --display fullscreen
    mindgrasp session run --subject S01 --plan my_plan.yaml
    mindgrasp session run --subject S01 --plan quick --robot xarm6   # trains on the lab's arm
    mindgrasp session resume --subject S01                       # after an interruption
    mindgrasp session calibrate --subject V01 --virtual-accuracy 0.9 --trials-per-class 10 --json
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import os
import sys
import time
from pathlib import Path

from mindgrasp_bringup.session import Session
from mindgrasp_bringup.session_plan import (
    SessionError,
    calibration_plan,
    check_subject,
    load_plan,
)
from mindgrasp_common.cli_checks import non_negative_int, positive_int, probability
from mindgrasp_common.robot_description import RobotDescriptionError, load_robot, robot_choices


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``mindgrasp session run`` and ``resume`` (the verb is the first argument)."""
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.epilog = __doc__
    parser.add_argument('--subject', required=True, help='subject ID (letters, digits, - and _)')
    parser.add_argument('--session', default=None,
                        help='session name (run: a new UTC timestamp; resume: the latest)')
    parser.add_argument('--root', default='subjects', help='folder of all subjects (subjects)')
    parser.add_argument('--plan', default='graded',
                        help='plan name (graded, quick, calibrate) or a plan YAML file')
    parser.add_argument('--amp', choices=['virtual', 'lsl'], default=None,
                        help='EEG source: virtual subject (default) or an LSL amplifier')
    parser.add_argument('--eeg-stream', default=None, help='LSL stream name of the amplifier')
    parser.add_argument('--display', choices=['off', 'window', 'fullscreen', 'headless'],
                        default=None, help="the participant's screen (default: window with "
                                           '--amp lsl, off for calibrate, else headless); the '
                                           'virtual subject with off runs in lock-step')
    parser.add_argument('--seed', type=non_negative_int, default=None,
                        help='seed of every phase (0)')
    parser.add_argument('--robot', default=None, metavar='NAME|YAML',
                        help='the arm of the Trainer and test phases (the user\'s arm and the '
                             'training robot, a second copy of it; default mindgrasp_arm): '
                             f'{robot_choices()}')
    if getattr(parser, 'prog', '').endswith('calibrate'):
        parser.set_defaults(plan='calibrate')
        parser.add_argument('--virtual-accuracy', type=probability, required=True, metavar='A',
                            help='probability that the virtual subject imagines the prompted '
                                 'class (0..1)')
        parser.add_argument('--trials-per-class', type=positive_int, required=True, metavar='N',
                            help='trials of each class in every training phase and in the '
                                 'held-out run')
        parser.add_argument('--json', action='store_true',
                            help='print the result as one JSON object on the last line')


def _launch_args(args: argparse.Namespace) -> dict[str, str]:
    out = {}
    for key, name in (('amp', 'amp'), ('eeg_stream', 'eeg_stream'), ('display', 'display'),
                      ('seed', 'seed'), ('robot', 'robot')):
        value = getattr(args, key)
        if value is not None:
            out[name] = str(value)
    return out


def _calibrate_result(session: Session, args: argparse.Namespace, t0: float) -> int:
    """Print the cross-validated and held-out accuracy (and JSON with --json)."""
    log = session.read_log()
    try:
        held = session.heldout_accuracy(log)
    except SessionError as err:
        print(f'mindgrasp session calibrate: {err}', file=sys.stderr)
        return 1
    cv = next(e['cv_accuracy'] for e in reversed(log['phases']) if 'cv_accuracy' in e)
    wall = time.monotonic() - t0
    temp = held['temperature']
    unseen = temp.get('unseen') or temp
    print(f'Calibrated {session.dir}: cross-validated accuracy {100 * cv:.1f} %, held-out '
          f"accuracy {100 * held['heldout_accuracy']:.1f} % on {held['heldout_trials']} trials "
          f'(virtual subject {100 * args.virtual_accuracy:.0f} %); probabilities calibrated on '
          f"the held-out run (temperature {temp['before']:.2f} -> {temp['after']:.2f}; on "
          f'windows it was not fitted on, the other half of that run: log loss '
          f"{unseen['nll_before']:.3f} -> {unseen['nll_after']:.3f} nats, expected calibration "
          f"error {unseen['ece_before']:.3f} -> {unseen['ece_after']:.3f}; the temperature "
          'minimises the log loss, the binned calibration error may still rise), model '
          f"{session.dir / held['model_path']}, {wall:.0f} s.")
    gate = held.get('gate') or {}
    if gate:
        from mindgrasp_common.answer_pair import AnswerPair

        pred = gate.get('predicted') or {}
        said = (AnswerPair.from_dict(held['answer_pair']).describe()
                if held.get('answer_pair') else '')
        print(f"Answer pair {(held.get('answer_pair') or {}).get('name', '-')} ({said}); "
              f"predicted {_pct(pred.get('correct_rate'))} correct, "
              f"{_pct(pred.get('wrong_rate'))} wrong grasps, "
              f"{_secs(pred.get('decision_time_s'))} per decision.")
        print(f"Calibration gate: {gate.get('verdict', '-')}: {gate.get('reason', '')}")
        report = session.dir / 'report.md'
        if report.exists():      # the session report tells the person how to answer
            with report.open('a', encoding='utf-8') as f:
                f.write(f"\n## Your answers\n\nAnswer pair **"
                        f"{(held.get('answer_pair') or {}).get('name', '-')}**: {said}.\n\n"
                        f"Calibration gate: **{gate.get('verdict', '-')}** "
                        f"({gate.get('reason', '')}); predicted {_pct(pred.get('correct_rate'))} "
                        f"correct and {_pct(pred.get('wrong_rate'))} wrong grasps, "
                        f"{_secs(pred.get('decision_time_s'))} per decision.\n")
    if args.json:
        print(json.dumps({'cv_accuracy': cv, 'heldout_accuracy': held['heldout_accuracy'],
                          'virtual_accuracy': args.virtual_accuracy,
                          'model_path': str((session.dir / held['model_path']).resolve()),
                          'heldout_trials': held['heldout_trials'],
                          'trained_model_path': str((session.dir / held['trained_model_path'])
                                                    .resolve()),
                          'temperature': temp,
                          'answer_pair': held.get('answer_pair'),
                          'decision_thresholds': held.get('decision_thresholds'),
                          'gate': held.get('gate'),
                          'session_dir': str(session.dir.resolve()),
                          'wall_time_s': round(wall, 1)}))
    return 0


def _pct(x: float | None) -> str:
    return 'n/a' if x is None else f'{100 * x:.0f} %'


def _secs(x: float | None) -> str:
    return 'n/a' if x is None else f'{x:.1f} s'


def main(args: argparse.Namespace) -> int:
    verb = args.verb
    t0 = time.monotonic()
    try:
        check_subject(args.subject)
        if args.robot is not None:    # one line before any phase starts
            try:
                load_robot(args.robot)
            except RobotDescriptionError as exc:
                raise SessionError(f'--robot: {exc}') from None
        root = Path(args.root)
        if verb in ('run', 'calibrate'):
            plan = load_plan(args.plan)
            if verb == 'calibrate':
                if args.amp == 'lsl':
                    msg = ('calibrate runs the virtual subject; for a person use mindgrasp '
                           'session run --amp lsl.')
                    raise SessionError(msg)
                plan = calibration_plan(plan, args.trials_per_class, args.virtual_accuracy,
                                        args.seed or 0)
            name = args.session or dt.datetime.now(dt.timezone.utc).strftime('%Y%m%dT%H%M%SZ')
            if args.amp == 'lsl' and not args.eeg_stream:
                msg = ("--amp lsl needs --eeg-stream NAME, the LSL stream name of the amplifier "
                       "(check it with: mindgrasp launch eeg eeg_stream:=NAME).")
                raise SessionError(msg)
            # the virtual amplifier's LSL stream is host-wide: a name of its own per session;
            # a person (a real amplifier) looks at a window; session run draws the virtual
            # subject's screen headless for the record; calibrate draws none, so its phases run
            # in lock-step (simulated time, as fast as the machine allows)
            stream = f'MIndGrasp-{args.subject}-{os.getpid()}'
            display = ('window' if args.amp == 'lsl' else
                       'off' if verb == 'calibrate' else 'headless')
            session = Session(root, args.subject, name,
                              {'display': display, 'seed': '0', 'eeg_stream': stream,
                               **_launch_args(args)})
            log = session.start(plan)
        else:
            name = args.session
            if name is None:
                found = sorted(p.parent.name for p in (root / args.subject).glob('*/session.yaml'))
                if not found:
                    msg = (f'No session of subject {args.subject} under {root}; start one with '
                           f'mindgrasp session run --subject {args.subject} --plan graded.')
                    raise SessionError(msg)
                name = found[-1]
            session = Session(root, args.subject, name, _launch_args(args))
            log = session.read_log()
            plan_file = session.dir / 'plan.yaml'
            import yaml

            plan_file.write_text(yaml.safe_dump(log['plan'], sort_keys=False), encoding='utf-8')
            plan = load_plan(str(plan_file))
            done = [e['name'] for e in log['phases'] if e['status'] == 'done']
            print(f'Resuming {session.dir}: done {", ".join(done) or "nothing yet"}.')
    except SessionError as err:
        print(f'mindgrasp session {verb}: {err}', file=sys.stderr)
        return 2
    print(f'Session {session.dir} ({plan.name}: {", ".join(p.name for p in plan.phases)})')
    try:
        code = session.run(plan, log)
        if code != 0 or verb != 'calibrate':
            return code
        return _calibrate_result(session, args, t0)
    except KeyboardInterrupt:
        print(f'Interrupted; finished phases are kept. Continue with: mindgrasp session resume '
              f'--subject {args.subject} --session {session.session}', file=sys.stderr)
        return 130
