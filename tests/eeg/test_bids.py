"""``mindgrasp export bids``: a calibration session (every phase) and an experiment run, recorded
for real, exported with mne-bids, accepted by the official validator (bids-validator-deno) and
read back with ``mne_bids.read_raw_bids``, events included."""

from __future__ import annotations

import csv
import json
import os
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import mne_bids
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.bids import bids_label, runs_to_export

pytestmark = pytest.mark.slow
MG = [sys.executable, '-m', 'mindgrasp_cli']
# what the export reads: EEG, annotations and the robot's motion (no camera images: a small bag)
EXPORT_TOPICS = ('/eeg/raw /trainer/prompt /task/target /task/result /fsm/state '
                 '/virtual_subject/intent /joint_states /ee_pose')


def _env() -> dict[str, str]:
    return {**os.environ, 'NO_COLOR': '1'}


@pytest.fixture(scope='module')
def recorded(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A lock-step calibration session (two phases, 2 trials per class) and a lock-step
    set-locations experiment run of one trial, recorded side by side."""
    tmp = tmp_path_factory.mktemp('bids')
    session = subprocess.Popen(
        [*MG, 'session', 'calibrate', '--subject', 'B01', '--session', 's1', '--root',
         str(tmp / 'subjects'), '--virtual-accuracy', '0.9', '--trials-per-class', '2',
         '--json'], env=_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    experiment = subprocess.Popen(
        [*MG, 'launch', 'experiment', 'subject:=virtual', 'accuracy:=1.0', 'trials:=1',
         f'record_topics:={EXPORT_TOPICS}', f'eeg_stream:=mg-bids-{uuid.uuid4().hex[:8]}',
         '--lockstep', '--run-dir', str(tmp / 'experiment')],
        env=_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    for proc in (session, experiment):
        out, _ = proc.communicate(timeout=900)
        assert proc.returncode == 0, out[-3000:]
    return {'session': tmp / 'subjects' / 'B01' / 's1', 'experiment': tmp / 'experiment',
            'root': tmp / 'bids'}


@pytest.fixture(scope='module')
def dataset(recorded: dict[str, Path]) -> Path:
    root = recorded['root']
    res = subprocess.run([*MG, 'export', 'bids', str(recorded['session']),
                          str(recorded['experiment']), '--root', str(root), '--subject', 'B01',
                          '--session', '1', '--reference', 'Cz', '--line-freq', '60'],
                         env=_env(), capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    assert res.stderr == '', res.stderr        # no warnings or tracebacks
    assert res.stdout.count('Wrote ') == 3, res.stdout
    return root


#: the official validator as the test extra installs it (its console script is not on PATH when
#: the venv is not activated, as under scripts/test.sh)
VALIDATOR = [sys.executable, '-c', 'import sys; from bids_validator_deno import cli; '
                                   'sys.exit(cli())']


def _errors(*args: str) -> tuple[int, list[dict], dict]:
    """Exit code, error issues and the summary of the validator run on ``args``."""
    res = subprocess.run([*VALIDATOR, *args, '--format', 'json'], capture_output=True, text=True,
                         timeout=300)
    report = json.loads(res.stdout)
    errors = [i for i in report['issues']['issues'] if i['severity'] == 'error']
    for deriv in report.get('derivativesSummary', {}).values():     # -r: each derivative
        errors += [i for i in deriv['issues']['issues'] if i['severity'] == 'error']
    return res.returncode, errors, report['summary']


def test_the_official_validator_accepts_the_dataset(dataset: Path) -> None:
    """From the root, as a user and OpenNeuro run it, and with -r, which also checks the robot
    motion's derivatives dataset (its files once had no BIDS name and were flagged)."""
    for args in ([str(dataset)], [str(dataset), '-r']):
        code, errors, summary = _errors(*args)
        assert code == 0 and not errors, (args, errors)
        assert sorted(summary['tasks']) == ['graz', 'setlocations']
    # the robot's motion, a derivatives dataset of its own, is valid on its own too
    code, errors, summary = _errors(str(dataset / 'derivatives' / 'mindgrasp'))
    assert code == 0 and not errors, errors
    assert summary['dataTypes'] == ['motion'] or 'motion' in summary.get('modalities', []), \
        summary


def _path(root: Path, task: str, run: int) -> mne_bids.BIDSPath:
    return mne_bids.BIDSPath(subject='B01', session='1', task=task, run=run, datatype='eeg',
                             root=root)


def test_every_session_phase_reads_back_with_its_prompts(dataset: Path) -> None:
    for run in (1, 2):     # 01_graz and 02_heldout: one protocol, two runs
        raw = mne_bids.read_raw_bids(_path(dataset, 'graz', run), verbose='error')
        assert raw.info['sfreq'] == 250.0 and len(raw.ch_names) == 32
        assert raw.info['line_freq'] == 60.0
        cues = [d for d in raw.annotations.description if d.startswith('prompt/cue/')]
        assert len(cues) == 8, sorted(set(raw.annotations.description))   # 2 trials x 4 classes
        assert raw.get_montage() is not None                             # electrodes.tsv
    sidecar = json.loads(_path(dataset, 'graz', 1).copy().update(
        suffix='eeg', extension='.json').fpath.read_text())
    assert sidecar['SamplingFrequency'] == 250.0 and sidecar['EEGReference'] == 'Cz'
    assert sidecar['PowerLineFrequency'] == 60.0
    # lock-step runs have no LSL stream, so no amplifier metadata: options, else n/a, as before
    assert sidecar['Manufacturer'] == 'n/a' and 'ManufacturersModelName' not in sidecar
    with open(_path(dataset, 'graz', 1).copy().update(suffix='channels', extension='.tsv')
              .fpath, encoding='utf-8') as f:
        channels = list(csv.DictReader(f, delimiter='\t'))
    assert {c['units'] for c in channels} == {'µV'} and channels[0]['type'] == 'EEG'


def test_the_experiment_run_has_targets_outcomes_states_and_robot_motion(dataset: Path) -> None:
    bids_path = _path(dataset, 'setlocations', 1)
    raw = mne_bids.read_raw_bids(bids_path, verbose='error')
    tags = {d.split('/')[0] for d in raw.annotations.description}
    assert {'target', 'result', 'state'} <= tags, tags
    with open(bids_path.copy().update(suffix='events', extension='.tsv').fpath,
              encoding='utf-8') as f:
        events = list(csv.DictReader(f, delimiter='\t'))
    assert list(events[0]) == ['onset', 'duration', 'trial_type', 'value', 'sample']
    assert any(e['trial_type'].startswith('result/') for e in events)
    # the bag kept as recorded, and the robot's joints and end-effector pose as a time series
    source = dataset / 'sourcedata' / 'sub-B01' / 'ses-1' / 'setlocations_run-1' / 'bag'
    assert (source / 'metadata.yaml').is_file()
    motion = next((dataset / 'derivatives' / 'mindgrasp').rglob(
        '*task-setlocations_tracksys-robot_run-1_motion.tsv'))
    with open(str(motion).replace('_motion.tsv', '_channels.tsv'), encoding='utf-8') as f:
        channels = list(csv.DictReader(f, delimiter='\t'))
    assert channels[0]['type'] == 'LATENCY' and channels[0]['units'] == 's'
    assert {'JNTANG', 'POS', 'ORNT'} <= {c['type'] for c in channels}
    sidecar = json.loads(motion.with_suffix('.json').read_text())
    assert sidecar['MotionChannelCount'] == len(channels) and sidecar['TaskName'] == 'setlocations'
    rows = [line.rstrip('\n').split('\t') for line in motion.read_text().splitlines()]
    assert len(rows) > 100 and all(len(r) == len(channels) for r in rows)


def test_bad_input_gets_one_line_and_writes_nothing(recorded: dict[str, Path],
                                                    tmp_path: Path) -> None:
    root = tmp_path / 'bids'
    bad_subject = subprocess.run([*MG, 'export', 'bids', str(recorded['experiment']), '--root',
                                  str(root), '--subject', 'B_01'], env=_env(),
                                 capture_output=True, text=True, timeout=120)
    assert bad_subject.returncode == 1 and bad_subject.stderr.splitlines() == [
        "mindgrasp export bids: --subject 'B_01' is not a BIDS label: use letters and digits "
        'only (e.g. --subject B01).']
    # a run without EEG: the experiment's bag without /eeg/raw
    no_eeg = tmp_path / 'no_eeg'
    shutil.copytree(recorded['experiment'] / 'params', no_eeg / 'params')
    from rosbags.rosbag2 import Reader, StoragePlugin, Writer

    with Reader(recorded['experiment'] / 'bag') as reader, \
            Writer(no_eeg / 'bag', version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data,
                                             rihs01=c.digest)
                 for c in reader.connections if c.topic == '/joint_states'}
        for conn, stamp, data in reader.messages([c for c in reader.connections
                                                  if c.id in conns]):
            writer.write(conns[conn.id], stamp, data)
    res = subprocess.run([*MG, 'export', 'bids', str(recorded['session']), str(no_eeg),
                          '--root', str(root), '--subject', 'B01'], env=_env(),
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 1
    assert len(res.stderr.splitlines()) == 1 and 'holds no EEG on' in res.stderr, res.stderr
    assert not root.exists()             # the session's runs were not written either


def test_labels_and_tasks() -> None:
    assert bids_label('B01', '--subject') == 'B01'
    with pytest.raises(EEGError, match=r"^--session 'pre-1' is not a BIDS label: use letters "
                                       r'and digits only \(e.g. --session pre1\)\.$'):
        bids_label('pre-1', '--session')
    with pytest.raises(EEGError, match='is neither a run directory with a bag nor a rosbag2'):
        runs_to_export(['/nonexistent/run'])


def test_a_session_exports_its_phases_in_order_one_task_per_protocol(
        recorded: dict[str, Path]) -> None:
    runs = runs_to_export([recorded['session'], recorded['experiment']])
    assert [(r.run_dir.name, r.task) for r in runs] == [
        ('01_graz', 'graz'), ('02_heldout', 'graz'), ('experiment', 'setlocations')]


def test_the_amplifier_metadata_comes_from_the_stream_and_options_override(
        recorded: dict[str, Path], tmp_path: Path, spawn_node) -> None:
    """A real amplifier stream (the virtual amplifier over LSL, declaring its manufacturer,
    model, reference and channel units) read by the real acquisition node, which keeps the
    metadata in its run directory; the export takes eeg.json's fields from it, options win."""
    run = tmp_path / 'run'
    shutil.copytree(recorded['experiment'], run)
    name = f'mg-bids-amp-{uuid.uuid4().hex[:8]}'
    spawn_node('mindgrasp_eeg.virtual_amp_node', stream_name=name, reference='Cz')
    acq = spawn_node('mindgrasp_eeg.acquisition_node', stream_name=name,
                     env={'MINDGRASP_RUN_DIR': str(run)})
    assert acq.wait_for_output('Stream metadata kept in', 60), acq.output()
    kept = json.loads((run / 'eeg_stream.json').read_text())
    assert (kept['manufacturer'], kept['model'], kept['reference']) == (
        'MIndGrasp', 'virtual amplifier', 'Cz')
    assert len(kept['channels']) == 32 and kept['channels'][0] == {
        'label': 'Fp1', 'unit': 'microvolts', 'type': 'EEG'}

    def eeg_json(root: Path, *options: str) -> dict:
        res = subprocess.run([*MG, 'export', 'bids', str(run), '--root', str(root),
                              '--subject', 'B01', *options], env=_env(), capture_output=True,
                             text=True, timeout=300)
        assert res.returncode == 0 and res.stderr == '', res.stderr[-3000:]
        bids_path = mne_bids.BIDSPath(subject='B01', task='setlocations', run=1,
                                      datatype='eeg', root=root, suffix='eeg',
                                      extension='.json')
        return json.loads(bids_path.fpath.read_text())

    sidecar = eeg_json(tmp_path / 'from_stream')
    assert (sidecar['Manufacturer'], sidecar['ManufacturersModelName'],
            sidecar['EEGReference']) == ('MIndGrasp', 'virtual amplifier', 'Cz')
    sidecar = eeg_json(tmp_path / 'options', '--reference', 'linked mastoids',
                       '--manufacturer', 'g.tec', '--model', 'g.Nautilus')
    assert (sidecar['Manufacturer'], sidecar['ManufacturersModelName'],
            sidecar['EEGReference']) == ('g.tec', 'g.Nautilus', 'linked mastoids')
    code, errors, _ = _errors(str(tmp_path / 'from_stream'), '-r')
    assert code == 0 and not errors, errors
