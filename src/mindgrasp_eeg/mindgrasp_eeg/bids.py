"""Export recorded runs as an EEG-BIDS dataset with mne-bids (ROS-free).

Each run directory (or every phase of a calibration session folder) becomes one BIDS EEG
recording::

    <root>/dataset_description.json, participants.tsv, README
    <root>/sub-<ID>[/ses-<S>]/eeg/sub-<ID>[_ses-<S>]_task-<task>_run-<n>_eeg.edf   EEG, volts
        ..._eeg.json        SamplingFrequency (the amplifier's), PowerLineFrequency, and
                            Manufacturer, ManufacturersModelName, EEGReference from the
                            amplifier's LSL metadata the acquisition node kept
                            (:mod:`.stream_metadata`; options override, 'n/a' without either)
        ..._channels.tsv    name, type (the stream's channel types where it declares them),
                            units (uV in the EDF header's physical unit)
        ..._events.tsv      onset, duration, trial_type, value, sample: the annotations of
                            :func:`mindgrasp_eeg.export.read_session` (prompts, targets, grasp
                            results, controller states, intents)
        ..._electrodes.tsv, ..._coordsystem.json   the standard_1020 montage
    <root>/sourcedata/sub-<ID>[/ses-<S>]/<task>_run-<n>/bag/   the run's rosbag2, as recorded
    <root>/derivatives/mindgrasp/sub-<ID>[/ses-<S>]/motion/
        ..._tracksys-robot_run-<n>_motion.tsv, _motion.json, _channels.tsv   the robot's joint
                            states and end-effector pose as BIDS motion data
                            (:mod:`.robot_motion`; written here, as mne-bids does not write
                            motion data), in a derivatives dataset with its own
                            dataset_description.json (GeneratedBy)

The task is the protocol: a session phase's kind (``graz``, ``grazfeedback``, ``trainer``), else
the run's trial manager protocol (``setlocations``, ``randomlocations``), else the prompter that
ran (``graz``, ``trainer``), else the launch profile; runs of one task are numbered in the order
given. The recording is written as EDF (mne-bids converts; EDF keeps volts as
physical values).
"""

from __future__ import annotations

import json
import re
import shutil
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from . import EEGError
from .export import find_bag, read_session, to_raw
from .robot_motion import read_robot_motion
from .stream_metadata import read_stream_metadata

__all__ = ['BidsRun', 'bids_label', 'export_bids', 'runs_to_export']

_LABEL = re.compile(r'^[A-Za-z0-9]+$')


@dataclass
class BidsRun:
    """One run to export: its run directory and its BIDS task label."""

    run_dir: Path
    task: str


def bids_label(value: str, option: str) -> str:
    """``value`` when it is a BIDS label (letters and digits only), else an EEGError."""
    if not _LABEL.match(value or ''):
        fixed = re.sub(r'[^A-Za-z0-9]', '', value or '') or 'S01'
        msg = (f'{option} {value!r} is not a BIDS label: use letters and digits only (e.g. '
               f'{option} {fixed}).')
        raise EEGError(msg)
    return value


def _task_label(text: str) -> str:
    return re.sub(r'[^A-Za-z0-9]', '', text).lower() or 'task'


def runs_to_export(paths: list[str | Path]) -> list[BidsRun]:
    """The runs of ``paths``: a session folder (with session.yaml) gives its finished phases in
    order, a run directory (or bag) itself.

    Raises:
        EEGError: a path that is neither.
    """
    runs: list[BidsRun] = []
    for path in map(Path, paths):
        log_file = path / 'session.yaml'
        if log_file.is_file():
            log = yaml.safe_load(log_file.read_text(encoding='utf-8')) or {}
            phases = {p['name']: p for p in (log.get('plan') or {}).get('phases', [])}
            done = [e for e in log.get('phases', []) if e.get('status') == 'done']
            if not done:
                msg = (f'The session {str(path)!r} has no finished phase to export; run or '
                       'resume it first (`mindgrasp session resume`).')
                raise EEGError(msg)
            for entry in done:
                spec = phases.get(entry['name'], {})
                kind = spec.get('kind', entry.get('kind', entry['name']))
                task = _task_label(kind + ('feedback' if spec.get('feedback') else ''))
                runs.append(BidsRun(path / entry['run_dir'], task))
            continue
        bag = find_bag(path)
        run_dir = bag.parent if bag.name == 'bag' else bag
        runs.append(BidsRun(run_dir, _task_label(_protocol(run_dir))))
    return runs


def _yaml(path: Path) -> dict:
    return (yaml.safe_load(path.read_text(encoding='utf-8')) or {}) if path.is_file() else {}


def _protocol(run_dir: Path) -> str:
    """The run's protocol: the parameter a node's class names as its task (the trial manager's
    ``protocol``: ``set_locations``, ...), else the phase kind of the prompter that ran
    (``graz``, ``trainer``), else the launch profile, else the folder name. Which node is which
    is asked of the node classes the run's launch.yaml lists (:func:`run_nodes`)."""
    from mindgrasp_ros.run_nodes import run_nodes

    nodes = run_nodes(run_dir)
    for node in nodes:
        if node.traits.task_parameter:
            for node_params in _yaml(run_dir / 'params' / f'{node.label}.yaml').values():
                task = (node_params or {}).get('ros__parameters', {}).get(
                    node.traits.task_parameter)
                if task:
                    return str(task)
    for node in nodes:
        if node.traits.prompts and not node.traits.task_parameter:
            return node.traits.prompts[0]
    return str(_yaml(run_dir / 'launch.yaml').get('profile') or run_dir.name)


def _answer_pair(run_dir: Path) -> Any:
    """The answer pair (:class:`mindgrasp_common.answer_pair.AnswerPair`) the run's scan
    controller used (its ``params/fsm.yaml``: ``answer_pair``, ``classifier_model``), None for a
    run without one."""
    from mindgrasp_common.answer_pair import DEFAULT_PAIR, answer_pair, model_decision
    from mindgrasp_common.errors import CommonError

    for section in _yaml(run_dir / 'params' / 'fsm.yaml').values():
        p = (section or {}).get('ros__parameters', {})
        if p.get('autonomous') or p.get('paradigm', 'scan') != 'scan':
            return None
        try:
            chosen = model_decision(p['classifier_model'])[0] if p.get('classifier_model') \
                else None
            name = str(p.get('answer_pair', 'auto'))
            if name == 'auto' or (chosen is not None and chosen.name == name):
                return chosen or answer_pair(DEFAULT_PAIR)
            return answer_pair(name)
        except CommonError:
            return None
    return None


def export_bids(paths: list[str | Path], root: str | Path, subject: str,
                session: str | None = None, *, line_freq: float = 50.0,
                reference: str | None = None, manufacturer: str | None = None,
                model: str | None = None, overwrite: bool = False) -> list[Path]:
    """Write the runs of ``paths`` into the BIDS dataset at ``root``; returns the EEG files.

    Args:
        paths: run directories, bags or session folders.
        root: the dataset's root (created; an existing dataset gets the new runs).
        subject: participant label (letters and digits).
        session: session label, or None for none.
        line_freq: power line frequency (Hz) for eeg.json (50 in Europe, 60 in the Americas).
        reference: the EEG reference for eeg.json (e.g. ``'Cz'``, ``'linked mastoids'``);
            None: the stream's (its LSL metadata, as the acquisition node kept it), else 'n/a'.
        manufacturer, model: the amplifier's, for eeg.json; None: the stream's, else 'n/a'
            (the model is left out without one).
        overwrite: replace runs that exist already.

    Raises:
        EEGError: a bad label, a run without EEG, or a run that exists already; the message
            says what to do.
    """
    import mne_bids

    bids_label(subject, '--subject')
    if session is not None:
        bids_label(session, '--session')
    runs = runs_to_export(paths)
    recordings = [(run, read_session(run.run_dir)) for run in runs]   # bad input before writing
    root = Path(root)
    counts: dict[str, int] = {}
    written = []
    for run, recording in recordings:
        counts[run.task] = counts.get(run.task, 0) + 1
        with warnings.catch_warnings():
            # MNE 1.13 renames the standard_1020 montage to_raw sets; the positions are the same
            warnings.simplefilter('ignore', FutureWarning)
            raw = to_raw(recording)
        raw.info['line_freq'] = float(line_freq)
        amp = read_stream_metadata(run.run_dir)
        _set_channel_types(raw, amp)
        bids_path = mne_bids.BIDSPath(subject=subject, session=session, task=run.task,
                                      run=counts[run.task], datatype='eeg', root=root)
        try:
            mne_bids.write_raw_bids(raw, bids_path, format='EDF', allow_preload=True,
                                    overwrite=overwrite, verbose='error')
        except FileExistsError as exc:
            msg = (f'{bids_path.basename} exists already in {str(root)!r}; pass --overwrite '
                   'or another --session.')
            raise EEGError(msg) from exc
        sidecar = bids_path.copy().update(suffix='eeg', extension='.json')
        fields = {
            'EEGReference': reference or amp.get('reference') or 'n/a', 'TaskName': run.task,
            'SoftwareFilters': 'n/a', 'RecordingType': 'continuous',
            'InstitutionName': 'n/a',
            'Manufacturer': manufacturer or amp.get('manufacturer') or 'n/a'}
        if model or amp.get('model'):
            fields['ManufacturersModelName'] = model or amp['model']
        pair = _answer_pair(run.run_dir)
        if pair is not None:        # the scan paradigm's yes / no imagery of this person
            fields['AnswerPair'] = pair.name
            fields['Instructions'] = (f'The arm offers each object in turn; {pair.describe()} '
                                      '(no also cancels an approach).')
        mne_bids.update_sidecar_json(sidecar, fields, verbose='error')
        source = root / 'sourcedata' / f'sub-{subject}' / (f'ses-{session}' if session else '') \
            / f'{run.task}_run-{counts[run.task]}'
        if source.exists():
            shutil.rmtree(source)
        shutil.copytree(find_bag(run.run_dir), source / 'bag')
        _write_motion(run.run_dir, recording.start_ns, root, bids_path)
        written.append(Path(str(bids_path.fpath)))
    return written


#: LSL channel <type> (XDF meta-data convention, any case) -> MNE channel type
_MNE_TYPES = {'eeg': 'eeg', 'eog': 'eog', 'emg': 'emg', 'ecg': 'ecg', 'misc': 'misc',
              'stim': 'stim', 'trigger': 'stim', 'resp': 'resp', 'gsr': 'gsr'}


def _set_channel_types(raw: object, amp: dict) -> None:
    """Give ``raw``'s channels the types the stream declared (``channels.tsv`` then says EOG,
    EMG ... where the amplifier said so); channels without a known type stay EEG."""
    kinds = {c.get('label'): _MNE_TYPES.get(str(c.get('type', '')).lower())
             for c in amp.get('channels', []) if isinstance(c, dict)}
    mapping = {name: kinds[name] for name in raw.ch_names
               if kinds.get(name) and kinds[name] != 'eeg'}
    if mapping:
        raw.set_channel_types(mapping, on_unit_change='ignore', verbose='error')


def _motion_channels(columns: list[str]) -> list[dict[str, str]]:
    """Rows of the motion ``channels.tsv`` (name, component, type, tracked_point, units) for the
    columns of :func:`~mindgrasp_eeg.robot_motion.read_robot_motion`: the onset is the LATENCY
    channel, joint positions JNTANG (rad), joint velocities MISC (rad/s; BIDS motion has no joint
    velocity type), the end effector POS (m) and ORNT (unit quaternion)."""
    rows = []
    for c in columns:
        if c == 'onset':
            row = ('n/a', 'LATENCY', 'n/a', 's')
        elif c.startswith('ee_q'):
            row = (f'quat_{c[-1]}', 'ORNT', 'end_effector', 'n/a')
        elif c.startswith('ee_'):
            row = (c[-1], 'POS', 'end_effector', 'm')
        elif c.endswith('_position'):
            row = ('n/a', 'JNTANG', c.removesuffix('_position'), 'rad')
        else:
            row = ('n/a', 'MISC', c.removesuffix('_velocity'), 'rad/s')
        rows.append(dict(zip(('name', 'component', 'type', 'tracked_point', 'units'),
                             (c, *row), strict=True)))
    return rows


def _write_motion(run_dir: Path, start_ns: int, root: Path, bids_path: object) -> None:
    """The robot's motion of one run as BIDS motion data (``tracksys-robot``) in the
    derivatives dataset ``derivatives/mindgrasp`` (nothing without joints). BIDS motion file
    names, so the validator accepts it, also when it checks the derivatives (``-r``)."""
    import mne_bids

    motion = read_robot_motion(find_bag(run_dir), start_ns)
    if motion is None:
        return
    columns, table = motion
    deriv = root / 'derivatives' / 'mindgrasp'
    if not (deriv / 'dataset_description.json').is_file():
        mne_bids.make_dataset_description(
            path=deriv, name='MIndGrasp robot motion', dataset_type='derivative',
            generated_by=[{'Name': 'mindgrasp export bids',
                           'Description': 'the robot arm\'s joint states and end-effector pose '
                                          'from each run\'s bag'}],
            source_datasets=[{'URL': '../..'}], overwrite=True, verbose='error')
        (deriv / 'README').write_text(
            'MIndGrasp robot motion: for each EEG run of the raw dataset (two folders up), the '
            "robot arm's joint states and end-effector pose as BIDS motion data "
            '(tracksys-robot), written by `mindgrasp export bids`.\n', encoding='utf-8')
    out = bids_path.copy().update(root=deriv, datatype='motion', suffix=None, extension=None,
                                  check=False)
    out.mkdir(exist_ok=True)
    # BIDS orders tracksys before run; mne-bids 0.20 writes it after, which the validator refuses
    stem = '_'.join(f'{key}-{value}' for key, value in (
        ('sub', out.subject), ('ses', out.session), ('task', out.task),
        ('tracksys', 'robot'), ('run', out.run)) if value is not None)
    fpath = Path(str(out.directory)) / f'{stem}_motion.tsv'
    # motion.tsv has no header: its columns are the rows of channels.tsv, in order; a value
    # missing (no pose yet) is BIDS's n/a
    fpath.write_text(''.join('\t'.join('n/a' if np.isnan(v) else f'{v:.6g}' for v in row) + '\n'
                             for row in table), encoding='utf-8')
    channels = _motion_channels(columns)
    with fpath.with_name(fpath.name.replace('_motion.tsv', '_channels.tsv')).open(
            'w', encoding='utf-8') as f:
        f.write('\t'.join(channels[0]) + '\n')
        f.writelines('\t'.join(row.values()) + '\n' for row in channels)
    duration = float(table[-1, 0] - table[0, 0]) if len(table) > 1 else 0.0
    counts: dict[str, int] = {}
    for row in channels:
        counts[row['type']] = counts.get(row['type'], 0) + 1
    sidecar = {
        'TaskName': bids_path.task, 'TrackingSystemName': 'robot',
        'Description': 'The robot arm\'s joint states (/joint_states) and end-effector pose '
                       '(/ee_pose) from the run\'s bag; the LATENCY channel is the time (s) '
                       'from the first EEG sample.',
        # the joint state rate, as measured: the bag's stamps, not a parameter
        'SamplingFrequency': round((len(table) - 1) / duration) if duration else 'n/a',
        'SamplingFrequencyEffective': round((len(table) - 1) / duration, 3) if duration else 'n/a',
        'RecordingDuration': round(duration, 3), 'MotionChannelCount': len(channels),
        **{f'{kind}ChannelCount': n for kind, n in counts.items() if kind != 'MISC'}}
    fpath.with_suffix('.json').write_text(json.dumps(sidecar, indent=1) + '\n',
                                          encoding='utf-8')
