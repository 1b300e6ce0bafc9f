"""Argument groups and printing shared by the train and evaluate commands."""

from __future__ import annotations

import argparse
import json
from typing import Any

from mindgrasp_classifier.data import Recording, load_inputs
from mindgrasp_common.cli_checks import bounded_int, finite_float
from mindgrasp_ros.topics import EEG_RAW, TRAINER_PROMPT, VIRTUAL_SUBJECT_INTENT


def add_data_arguments(parser: argparse.ArgumentParser) -> None:
    """Input options: EDF files, EEGMMIDB through MNE, recorded run bags."""
    g = parser.add_argument_group('data')
    g.add_argument('--edf', nargs='+', default=[], metavar='FILE',
                   help='EEG files with annotations (EDF/BDF/GDF); EEGMMIDB SxxxRyy.edf files are '
                        'labelled automatically')
    g.add_argument('--xdf', nargs='+', default=[], metavar='FILE',
                   help='XDF recordings (LabRecorder: the EEG and the MIndGrasp-Markers stream; '
                        'cues are its prompt markers, or those named in --event-map)')
    g.add_argument('--bag', nargs='+', default=[], metavar='RUN',
                   help='recorded runs (rosbag2 folders or run directories) with /eeg/raw and '
                        '/trainer/prompt')
    g.add_argument('--eegbci', type=bounded_int(1, 109), metavar='SUBJECT',
                   help='EEGMMIDB subject loaded through MNE (MNE_DATASETS_EEGBCI_PATH)')
    g.add_argument('--runs', type=bounded_int(1, 14), nargs='+', default=[], metavar='RUN',
                   help='EEGMMIDB runs for --eegbci (default 4 6 8 10)')
    g.add_argument('--event-map', metavar='MAP',
                   help='annotation to class for other files, e.g. T1=left_hand,T2=right_hand')
    g.add_argument('--eeg-topic', default=EEG_RAW.name, help='EEG topic in bags (default /eeg/raw)')
    g.add_argument('--prompt-topic', default=TRAINER_PROMPT.name,
                   help='prompt topic in bags (default /trainer/prompt)')
    g.add_argument('--labels', choices=('prompt', 'intent', 'markers'), default='prompt',
                   help='labels of bag runs: the trainer/Graz prompts (prompt, default), the '
                        "virtual subject's intent for demo and experiment runs (intent, from "
                        '--intent-topic; epochs [tmin, tmax] tile each intent), or the '
                        "amplifier's LSL markers on /eeg/markers named in --event-map (markers)")
    g.add_argument('--intent-topic', default=VIRTUAL_SUBJECT_INTENT.name,
                   help='intent topic in bags for --labels intent (default '
                        '/virtual_subject/intent)')
    g.add_argument('--keep-aborted', action='store_true',
                   help='keep trainer trials cut short by a robot reset (left out by default: '
                        'their epochs hold rest and the next trial)')
    g.add_argument('--rest', action='store_true',
                   help="label rest epochs as class 'rest' (EEGMMIDB: the T0 annotations; other "
                        'files: map their rest annotation in --event-map, e.g. T0=rest)')
    g.add_argument('--tmin', type=finite_float, default=0.5,
                   help='epoch start after the cue (s, 0.5)')
    g.add_argument('--tmax', type=finite_float, default=2.5,
                   help='epoch end after the cue (s, 2.5)')


def load_from_args(args: argparse.Namespace, rest: bool = False) -> list[Recording]:
    """Recordings named by :func:`add_data_arguments` options; ``rest`` (or ``--rest``) labels
    rest epochs."""
    recordings = load_inputs(edf=args.edf, bags=args.bag, event_map=args.event_map,
                             eegbci_subject=args.eegbci, eegbci_runs=args.runs,
                             eeg_topic=args.eeg_topic, prompt_topic=args.prompt_topic,
                             labels=args.labels, keep_aborted=args.keep_aborted,
                             intent_topic=args.intent_topic, tmin=args.tmin, tmax=args.tmax,
                             rest=rest or args.rest, xdf=args.xdf)
    aborted = sum(r.n_aborted for r in recordings)
    if aborted:
        print(f"{'Kept' if args.keep_aborted else 'Left out'} {aborted} aborted trial(s) "
              '(cut short by a robot reset)' + ('' if args.keep_aborted else
                                                 '; --keep-aborted keeps them') + '.')
    return recordings


def format_report(report: dict[str, Any], title: str) -> str:
    """Human-readable accuracy, confusion matrix and certainty distribution."""
    names = report['classes']
    lines = [title,
             f"  trials: {report['n_trials']} ({report.get('trials_per_class', {})}), "
             f"windows: {report['n_windows']}",
             f"  accuracy (per trial):        {100 * report['accuracy']:.1f} %  "
             f"(chance {100 * report['chance']:.1f} %)",
             f"  balanced accuracy:           {100 * report['balanced_accuracy']:.1f} %",
             f"  window accuracy:             {100 * report['window_accuracy']:.1f} %",
             '  confusion (rows true, columns predicted):']
    width = max(len(n) for n in names) + 2
    lines.append(' ' * (width + 4) + ''.join(f'{n[:12]:>13}' for n in names))
    for name, row in zip(names, report['confusion'], strict=True):
        lines.append(f'    {name:<{width}}' + ''.join(f'{v:>13d}' for v in row))
    lines.append('  certainty per true class (windows): mean +- sd [q25 median q75]')
    for name, st in report['certainty'].items():
        lines.append(f"    {name:<{width}}{st['mean']:.3f} +- {st['std']:.3f} "
                     f"[{st['q25']:.3f} {st['median']:.3f} {st['q75']:.3f}]")
    return '\n'.join(lines)


def _pct(value: float | None) -> str:
    return 'n/a' if value is None else f'{100 * value:.1f} %'


def format_cv_report(report: dict[str, Any]) -> str:
    """Cross-validation of :func:`~mindgrasp_classifier.training.cross_validate_model`: the
    scheme, the confound sentence, per held-out run and the optimistic figure, calibration."""
    if report['scheme'] == 'trial_grouped_kfold':
        text = format_report(report, f"Cross-validation ({report['folds']} folds, grouped by "
                                     'trial; scheme trial_grouped_kfold, one recording):')
    elif report['n_trials']:
        text = format_report(report, f"Cross-validation (leave_one_run_out over {report['folds']} "
                                     'recordings; scored classes: '
                                     f"{', '.join(report['scored_classes'])}):")
    else:
        text = ('Cross-validation (leave_one_run_out over '
                f"{report['folds']} recordings): no held-out trial has a class that the other "
                'recordings contain, so it measures nothing here.')
    lines = [text]
    if report['scheme'] == 'leave_one_run_out':
        if report.get('confound'):
            lines.append(f"  {report['confound']}")
        lines.append('  per held-out recording (trial accuracy / balanced / window accuracy on '
                     'the scored classes):')
        for run in report['per_run']:
            scored = ', '.join(run['scored_classes']) or 'none'
            lines.append(f"    {run['recording']}: {_pct(run['accuracy'])} / "
                         f"{_pct(run['balanced_accuracy'])} / {_pct(run['window_accuracy'])}  "
                         f"({run['n_trials']} trials of {scored}; it has "
                         f"{', '.join(run['classes'])})")
        if report['n_unscored_trials']:
            lines.append(f"  {report['n_unscored_trials']} trial(s) not scored: their class is "
                         'missing from the other recordings.')
        opt = report.get('optimistic')
        if opt:
            lines.append(f"  optimistic (trial_grouped_kfold, {opt['folds']} folds over all "
                         f"recordings): accuracy {_pct(opt['accuracy'])}, balanced "
                         f"{_pct(opt['balanced_accuracy'])}, window {_pct(opt['window_accuracy'])}")
    cal = report.get('calibration')
    if cal and cal.get('source'):
        lines.append(f"  probability calibration (held-out windows of {cal['source']}, "
                     f"{cal['n_windows']}): temperature {cal['temperature']:.3f}; ECE "
                     f"{_pct(cal['ece_uncalibrated'])} -> {_pct(cal['ece'])}, NLL "
                     f"{cal['nll_uncalibrated']:.3f} -> {cal['nll']:.3f}")
    return '\n'.join(lines)


def print_json(obj: Any) -> None:
    """The machine-readable result as the last line of output."""
    print(json.dumps(obj, separators=(',', ':')))
