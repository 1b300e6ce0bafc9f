"""``mindgrasp experiment population``: the population file and subjects, the per-subject table
and the figures across subjects as plain functions, and a population of 2 real EEGMMIDB subjects
x 2 trials end to end (the experiment profile's real nodes in lock-step, in a subprocess):
resumed after a kill, and on a real 2-node Ray cluster (``ray start --head`` and a second node
process on this machine, listening on 127.0.0.1 only), each with the records of the local run."""

from __future__ import annotations

import csv
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from mindgrasp_experiments import ExperimentError
from mindgrasp_experiments.population import (
    PopulationSubject,
    expressible_pairs,
    load_population,
    population_figures,
    resolve_subjects,
    restricted_pair,
    subject_row,
    targets,
)

from .test_experiment_cli import last_json, mindgrasp

ROOT = Path(__file__).resolve().parents[2]
LOCAL = ROOT / 'docs' / 'populations' / 'eegmmidb_local.yaml'
#: the population every end-to-end test runs: 2 subjects x 2 trials, short trials
SUBJECTS = 'eegmmidb:1,eegmmidb:2'
RUN = ('--trials', '2', '--seed', '3', '--trial-timeout', '20', '--no-progress')
#: a generous bound for one population run on a loaded machine (s)
RUN_TIMEOUT = 3000.0


def test_the_local_population_file_lists_the_11_subjects_with_their_runs() -> None:
    subjects = resolve_subjects(load_population(LOCAL))
    assert [s.label for s in subjects] == ['eegmmidb_s001', *(
        f'eegmmidb_s{n:03d}' for n in (2, 3, 4, 6, 7, 8, 9, 10, 11, 12))]
    by = {s.label: s for s in subjects}
    assert by['eegmmidb_s002'].calibration == tuple(f'eegbci:2:{r}' for r in (4, 6, 8, 10))
    assert by['eegmmidb_s002'].play == ('eegbci:2:12', 'eegbci:2:14')
    assert not by['eegmmidb_s002'].restricted and by['eegmmidb_s002'].group == 'tuning'
    s6 = by['eegmmidb_s006']
    assert s6.calibration == ('eegbci:6:4', 'eegbci:6:6', 'eegbci:6:8')
    assert s6.play == ('eegbci:6:12',) and s6.group == 'unseen'
    # run 12 holds left and right fist only: the pairs it can express are said
    assert s6.restricted and s6.play_classes == ('left_hand', 'right_hand')
    assert s6.restriction() == ('play data holds left_hand, right_hand and rest only: answer '
                                'pairs restricted to left_right')


def test_expressible_pairs_follow_the_contract_names() -> None:
    every = ('left_hand', 'right_hand', 'both_hands', 'both_feet')
    assert expressible_pairs(every) == [
        'hands_feet', 'left_right', 'mi_rest', 'left_hand_both_hands', 'left_hand_both_feet',
        'right_hand_both_hands', 'right_hand_both_feet']
    assert expressible_pairs(('both_feet',), rest=False) == []


@pytest.mark.parametrize(('text', 'message'), [
    ('subjects: []\n', 'a non-empty subjects: list'),
    ('subjects: [eegmmidb:1]\nname: x\nseed: 3\n', "not \\['seed'\\]"),
    ('subjects: [{subject: eegmmidb:1, colour: red}]\n', 'subject 1 must be'),
    ('subjects: [eegmmidb:1\n', 'not valid YAML'),
])
def test_a_bad_population_file_is_named(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / 'pop.yaml'
    path.write_text(text)
    with pytest.raises(ExperimentError, match=message):
        load_population(path)


def test_subjects_must_be_replay_subjects_given_once() -> None:
    with pytest.raises(ExperimentError, match='a population runs replay subjects'):
        resolve_subjects([{'subject': 'virtual'}])
    with pytest.raises(ExperimentError, match='given twice'):
        resolve_subjects([{'subject': 'eegmmidb:1'}, {'subject': 'eegmmidb:1'}])


def _subject(**kw) -> PopulationSubject:
    return PopulationSubject(**{'subject': 'eegmmidb:6', 'label': 'eegmmidb_s006',
                                'play_classes': ('left_hand', 'right_hand'), **kw})


def _summary(correct: int, wrong: int, trials: int = 18, **extra) -> dict:
    return {'summary': {'trials': trials, 'correct_and_successful_count': correct,
                        'correct_and_successful_rate': correct / trials,
                        'correct_and_successful_ci95': [0.1, 0.9], 'wrong_grasp_count': wrong,
                        'wrong_grasp_rate': wrong / trials, 'wrong_grasp_ci95': [0.0, 0.2],
                        'no_grasp_count': trials - correct - wrong,
                        'no_grasp_rate': (trials - correct - wrong) / trials,
                        'no_grasp_ci95': [0.0, 0.3], 'median_time_to_correct_grasp_s': 50.0,
                        'itr_bits_per_min': 2.0, **extra},
            'run': {'wall_s': 10.0, 'sim_s': 100.0}}


def test_a_row_reads_the_contract_keys_or_leaves_them_absent() -> None:
    row = subject_row(_subject(), _summary(12, 1))
    assert row['correct_count'] == 12 and row['wrong_grasp_count'] == 1
    assert row['answer_pair'] is None and row['gate_verdict'] is None
    assert row['predicted_correct_rate'] is None
    row = subject_row(_subject(), _summary(12, 1, answer_pair='left_right',
                                           gate_verdict='ready', predicted_correct_rate=0.7))
    assert (row['answer_pair'], row['gate_verdict'], row['predicted_correct_rate']) == \
        ('left_right', 'ready', 0.7)
    missing = subject_row(_subject(), None, status='not run: no EEG')
    assert missing['trials'] is None and missing['status'] == 'not run: no EEG'


def test_figures_across_subjects() -> None:
    rows = [subject_row(_subject(label=f's{i}'), _summary(c, w, predicted_correct_rate=p,
                                                          gate_verdict=v))
            for i, (c, w, p, v) in enumerate([(18, 0, 0.9, 'ready'), (9, 1, 0.2, 'ready'),
                                               (3, 0, 0.1, 'not_ready'),
                                               (14, 2, 0.75, 'ready')])]
    rows.append(subject_row(_subject(label='x'), None, status='not run: x'))
    fig = population_figures(rows)
    assert fig['subjects'] == 5 and fig['subjects_run'] == 4 and fig['trials'] == 72
    assert fig['correct_rate']['median'] == pytest.approx((9 + 14) / 2 / 18)
    assert fig['pooled_wrong_grasp_rate'] == pytest.approx(3 / 72)
    low, high = fig['pooled_wrong_grasp_ci95']
    assert low < 3 / 72 < high
    assert fig['max_wrong_grasps_per_subject'] == 2
    assert fig['share_at_least_half_correct'] == 0.75          # 18, 9, 14 of 18
    # |0.9-1.0|, |0.2-0.5|, |0.1-0.17|, |0.75-0.78|: 3 of 4 within 20 points
    assert fig['share_predicted_within_20_points'] == 0.75
    assert fig['share_of_ready_at_least_half_correct'] == 1.0
    verdicts = {t: v for t, _m, v in targets(fig)}
    assert verdicts['pooled wrong grasps <= 3 % of trials'] == 'missed'
    assert verdicts['>= 75 % of subjects at >= 50 % correct'] == 'met'


def test_a_choice_the_play_data_cannot_express_is_replaced(tmp_path: Path) -> None:
    model = tmp_path / 'model.json'
    gate = {'verdict': 'ready', 'pairs': [
        {'name': 'hands_feet', 'heldout_accuracy': 0.9},
        {'name': 'left_right', 'heldout_accuracy': 0.7},
        {'name': 'mi_rest', 'heldout_accuracy': 0.75}]}
    model.write_text(json.dumps({'answer_pair': {'name': 'hands_feet', 'yes': ['both_hands'],
                                                 'no': ['both_feet']}, 'gate': gate}))
    pair, note = restricted_pair(_subject(), model)
    assert pair == 'mi_rest' and 'cannot express it' in note
    model.write_text(json.dumps({'answer_pair': {'name': 'left_right', 'yes': ['right_hand'],
                                                 'no': ['left_hand']}, 'gate': gate}))
    assert restricted_pair(_subject(), model) == (None, '')
    model.write_text(json.dumps({'classes': ['left_hand']}))     # a build without the pair
    pair, note = restricted_pair(_subject(), model)
    assert pair is None and 'names no answer pair' in note


def test_the_gate_keeps_a_subject_who_is_not_ready_from_the_arm(tmp_path: Path) -> None:
    """--gate ready (the default): a subject the calibration gate does not call ready gets a
    row with the verdict, reason and prediction and no trials, as the hardware launch refuses
    its model; a ready one drives the arm."""
    from mindgrasp_experiments.population import _gate_row

    model = tmp_path / 'model.json'
    model.write_text(json.dumps({
        'answer_pair': {'name': 'mi_rest', 'yes': ['left_hand'], 'no': ['rest']},
        'gate': {'verdict': 'not_ready', 'reason': 'no answer pair decodes',
                 'predicted': {'correct_rate': 0.13, 'wrong_rate': 0.87,
                               'decision_time_s': 9.6}}}))
    row = _gate_row(_subject(), model)
    assert row is not None and row['trials'] is None
    assert row['status'].startswith('not run: the calibration gate says not_ready (no answer '
                                    'pair decodes)')
    assert (row['gate_verdict'], row['answer_pair'], row['predicted_correct_rate']) == \
        ('not_ready', 'mi_rest', 0.13)
    figures = population_figures([row])
    assert figures['subjects_run'] == 0 and figures['subjects_kept_from_the_arm'] == 1
    model.write_text(json.dumps({'gate': {'verdict': 'ready'}}))
    assert _gate_row(_subject(), model) is None
    model.write_text('{}')          # a model without a verdict is not ready either
    assert _gate_row(_subject(), model)['gate_verdict'] == 'unassessed'


def test_bad_arguments_are_one_line() -> None:
    for args, message in ((('--subjects', 'virtual'), 'a population runs replay subjects'),
                          ((), 'give the subjects'),
                          (('--population', 'nowhere.yaml'), 'cannot read it'),
                          (('--subjects', 'eegmmidb:1', '--param', 'fsm.x=1,2'),
                           'one value per parameter')):
        result = mindgrasp('experiment', 'population', *args, timeout=120)
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1 and message in lines[0], result.stderr


def _records(out: Path) -> dict[str, str]:
    return {d.name: (d / 'records.csv').read_text()
            for d in sorted((out / 'subjects').iterdir())}


@pytest.fixture(scope='module')
def population(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """A population of 2 subjects x 2 trials on 2 workers."""
    out = tmp_path_factory.mktemp('population') / 'run'
    doc = last_json(mindgrasp('experiment', 'population', '--subjects', SUBJECTS, *RUN,
                              '--workers', '2', '--out', str(out), '--json',
                              timeout=RUN_TIMEOUT))
    return out, doc


@pytest.mark.slow
@pytest.mark.timeout(7200)
def test_a_population_of_2_subjects_x_2_trials(population: tuple[Path, dict]) -> None:
    out, doc = population
    assert [s['label'] for s in doc['subjects']] == ['eegmmidb_s001', 'eegmmidb_s002']
    assert all(s['trials'] == 2 and s['status'] == 'done' for s in doc['subjects'])
    assert doc['population']['subjects_run'] == 2 and doc['population']['trials'] == 4
    for s in doc['subjects']:
        assert s['correct_count'] + s['wrong_grasp_count'] + s['no_grasp_count'] == 2
    with (out / 'population.csv').open() as stream:
        rows = list(csv.DictReader(stream))
    assert [r['label'] for r in rows] == ['eegmmidb_s001', 'eegmmidb_s002']
    for stem in ('population_outcomes', 'predicted_vs_measured'):
        assert (out / f'{stem}.png').stat().st_size > 0 and (out / f'{stem}.svg').exists()
    report = (out / 'report.md').read_text()
    assert '| eegmmidb_s002 |' in report and 'calibrated on eegbci:2:4, eegbci:2:6' in report
    assert 'pooled wrong grasps' in report
    for label in ('eegmmidb_s001', 'eegmmidb_s002'):
        assert (out / 'subjects' / label / 'summary.json').exists()
    # the same --out again: nothing to run, the same table
    before = (out / 'population.csv').read_text()
    result = mindgrasp('experiment', 'population', '--subjects', SUBJECTS, *RUN,
                       '--out', str(out), timeout=RUN_TIMEOUT)
    assert result.returncode == 0, result.stderr
    assert (out / 'population.csv').read_text() == before
    assert _records(out) == {label: (out / 'subjects' / label / 'records.csv').read_text()
                             for label in ('eegmmidb_s001', 'eegmmidb_s002')}
    # other options for the same --out: one line, nothing run
    other = [('3' if RUN[i - 1] == '--trials' else a) for i, a in enumerate(RUN)]
    result = mindgrasp('experiment', 'population', '--subjects', SUBJECTS, *other,
                       '--out', str(out))
    assert result.returncode == 2 and 'other options (trials)' in result.stderr, result.stderr


@pytest.mark.slow
@pytest.mark.timeout(7200)
def test_the_two_subjects_get_different_answer_pairs(population: tuple[Path, dict]) -> None:
    """The replay subjects' own calibration (replay_model, made once by the population run):
    S001 (calibrated on runs 4, 6) answers with both hands / both feet, S002, whose both hands /
    both feet decode worst, with another pair (left / right hand)."""
    chosen = {}
    for n in (1, 2):
        [path] = (population[0] / 'models').glob(f'eegmmidb_s00{n}_classifier_*.json')
        model = json.loads(path.read_text())
        chosen[n] = model['answer_pair']['name']
        assert model['gate']['verdict'] in ('ready', 'needs_training', 'not_ready')
        assert set(model['decision_thresholds']) == {'confirm', 'pass', 'affirm', 'cancel'}
    assert chosen[1] == 'hands_feet' and chosen[2] != 'hands_feet', chosen


def _with_models_of(population: tuple[Path, dict], out: Path) -> Path:
    """``out`` holding the calibrated models of the ``population`` run (found by their digest:
    the same calibration is not made again; what a test checks is how the trials run)."""
    out.mkdir()
    shutil.copytree(population[0] / 'models', out / 'models')
    return out


@pytest.mark.slow
@pytest.mark.timeout(7200)
def test_a_killed_population_continues_with_the_same_records(
        population: tuple[Path, dict], tmp_path: Path) -> None:
    out = _with_models_of(population, tmp_path / 'run')
    command = [sys.executable, '-m', 'mindgrasp_cli', 'experiment', 'population', '--subjects',
               SUBJECTS, *RUN, '--workers', '1', '--out', str(out)]
    first = out / 'subjects' / 'eegmmidb_s001' / 'summary.json'
    with subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                          env=dict(os.environ)) as proc:
        deadline = time.monotonic() + RUN_TIMEOUT
        while not first.exists() and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.2)
        assert first.exists(), 'the first subject never finished'
        proc.send_signal(signal.SIGKILL)        # killed, not interrupted: nothing is tidied up
        proc.wait()
    assert not (out / 'population.json').exists()
    result = mindgrasp('experiment', 'population', '--subjects', SUBJECTS, *RUN, '--workers',
                       '1', '--out', str(out), timeout=RUN_TIMEOUT)
    assert result.returncode == 0, result.stderr
    assert _records(out) == _records(population[0])
    assert (out / 'population.csv').read_text().splitlines()[1].split(',')[:12] == \
        (population[0] / 'population.csv').read_text().splitlines()[1].split(',')[:12]


# -- a real Ray cluster -----------------------------------------------------------------------

HOST = '127.0.0.1'
#: how long the cluster gets to come up on a loaded machine (s)
START_TIMEOUT = 180.0


def _free_port() -> int:
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def _ray_start(args: list[str], temp_dir: str, log: Path) -> subprocess.Popen:
    """``ray start --block`` in a process group of its own (its servers and workers too)."""
    ray = str(Path(sys.executable).with_name('ray'))
    env = dict(os.environ)
    with log.open('w') as stream:
        return subprocess.Popen(
            [ray, 'start', '--block', '--num-cpus', '1',
             '--temp-dir', temp_dir, '--disable-usage-stats',
             '--dashboard-agent-listen-port', str(_free_port()),
             '--metrics-export-port', str(_free_port()), *args],
            stdout=stream, stderr=subprocess.STDOUT, env=env, start_new_session=True)


def _stop(proc: subprocess.Popen) -> None:
    """End a ``ray start --block`` and everything of its process group."""
    for sig, wait in ((signal.SIGTERM, 30), (signal.SIGKILL, 10)):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=wait)
        except subprocess.TimeoutExpired:
            continue
        # the group's other processes (raylet, GCS, workers) may outlive the leader
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        return


def _alive_nodes(address: str) -> int:
    """Alive nodes of the cluster, asked by a Ray driver in a subprocess."""
    code = (f'import ray; ray.init(address={address!r}, log_to_driver=False, '
            'include_dashboard=False); '
            'print(sum(n["Alive"] for n in ray.nodes()))')
    result = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                            timeout=120, check=False)
    try:
        return int(result.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return 0


@pytest.fixture
def ray_cluster(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """A 2-node Ray cluster on this machine (head + a second node process), reached at
    127.0.0.1; its address. Ray 2.60 takes no loopback node address (``ray start`` turns
    127.0.0.1 into the machine's address) and its servers listen on every interface, so the
    cluster takes a token of this test only (``RAY_AUTH_MODE=token``): nobody else can join it
    or run code on it. The finalizer ends the two ``ray start --block`` process groups it
    started (never ``ray stop``: that would end other Ray instances of this machine too)."""
    pytest.importorskip('ray', reason='the optional extra cluster: pip install -e ".[cluster]"')
    monkeypatch.setenv('RAY_AUTH_MODE', 'token')
    monkeypatch.setenv('RAY_AUTH_TOKEN', secrets.token_hex(32))
    monkeypatch.setenv('RAY_USAGE_STATS_ENABLED', '0')
    port = _free_port()
    address = f'{HOST}:{port}'
    # short paths: Ray's Unix sockets live in the temp dir (at most 107 characters)
    temps = [tempfile.mkdtemp(prefix='mgray'), tempfile.mkdtemp(prefix='mgray')]
    procs: list[subprocess.Popen] = []
    try:
        procs.append(_ray_start(['--head', '--port', str(port), '--include-dashboard', 'false'],
                                temps[0], tmp_path / 'head.log'))
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline:
            try:
                socket.create_connection((HOST, port), timeout=2).close()
                break
            except OSError:
                assert procs[0].poll() is None, (tmp_path / 'head.log').read_text()
                time.sleep(1)
        procs.append(_ray_start(['--address', address], temps[1], tmp_path / 'node.log'))
        while _alive_nodes(address) < 2:
            assert time.monotonic() < deadline, (
                'the second Ray node never joined:\n' + (tmp_path / 'node.log').read_text())
            assert procs[1].poll() is None, (tmp_path / 'node.log').read_text()
            time.sleep(2)
        yield address
    finally:
        for proc in reversed(procs):
            _stop(proc)
        for temp in temps:
            shutil.rmtree(temp, ignore_errors=True)


@pytest.mark.slow
@pytest.mark.timeout(7200)
def test_a_population_on_a_two_node_ray_cluster_gives_the_local_records(
        population: tuple[Path, dict], ray_cluster: str, tmp_path: Path) -> None:
    out = _with_models_of(population, tmp_path / 'run')
    doc = last_json(mindgrasp('experiment', 'population', '--subjects', SUBJECTS, *RUN,
                              '--ray', ray_cluster, '--out', str(out), '--json',
                              timeout=RUN_TIMEOUT))
    assert doc['run']['ray'] == ray_cluster
    assert _records(out) == _records(population[0])
