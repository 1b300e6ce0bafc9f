"""Labelled data from recorded run bags and EDF files, and the train/evaluate commands."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from mindgrasp_classifier.data import intent_events, load_bag, parse_event_map
from mindgrasp_classifier.errors import ClassifierError

from .classifier_synth import RATE, make_recording

NO_CLASS = 255


def write_run_bag(path, rec, t0=500.0, chunk=4, drop=(40, 41), writer_kind='rosbags', abort=(),
                  intent=False):
    """A rosbag2 (MCAP) with /eeg/raw chunks and Graz prompts, as a recorded run would have.

    ``abort``: trials (from 1) cut short 0.22 s after their cue (a robot reset); ``intent``: the
    virtual subject's /virtual_subject/intent (class name at each cue, 'rest' 3 s later)."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from mindgrasp_ros.typesupport import typestore

    store = typestore()
    eeg_t, prompt_t = 'mindgrasp_msgs/msg/EEGChunk', 'mindgrasp_msgs/msg/Prompt'
    chunk_cls, prompt_cls = store.types[eeg_t], store.types[prompt_t]
    string_t = 'std_msgs/msg/String'
    names = ('left_hand', 'right_hand', 'both_hands', 'both_feet')
    msgs = []
    for i, k in enumerate(range(0, rec.data.shape[0], chunk)):
        if i in drop:
            continue
        block = rec.data[k:k + chunk]
        m = chunk_cls(sample_rate=rec.rate, channel_names=list(rec.channels),
                      n_samples=block.shape[0], first_sample_index=k + 1000, unit='V',
                      data=block.astype(np.float32).ravel())
        ns = round((t0 + k / rec.rate) * 1e9)
        m.header.stamp.sec, m.header.stamp.nanosec = ns // 10**9, ns % 10**9
        msgs.append((ns, '/eeg/raw', eeg_t, m))
    for trial, (onset, cls) in enumerate(rec.events, start=1):
        cut = 0.22 if trial in abort else 3.0
        for dt, c, phase in ((-1.0, NO_CLASS, 'fixation'), (0.0, int(cls), 'cue'),
                             (cut, NO_CLASS, 'rest')):
            ns = round((t0 + onset / rec.rate + dt) * 1e9)
            p = prompt_cls(paradigm='graz', class_index=c, phase=phase, trial=trial,
                           duration=3.0)
            p.header.stamp.sec, p.header.stamp.nanosec = ns // 10**9, ns % 10**9
            msgs.append((ns, '/trainer/prompt', prompt_t, p))
        if intent:
            for dt, name in ((0.0, names[int(cls)]), (3.0, 'rest')):
                ns = round((t0 + onset / rec.rate + dt) * 1e9)
                msgs.append((ns, '/virtual_subject/intent', string_t,
                             store.types[string_t](data=name)))
    msgs.sort(key=lambda x: x[0])
    topics = (('/eeg/raw', eeg_t), ('/trainer/prompt', prompt_t)) + (
        (('/virtual_subject/intent', string_t),) if intent else ())
    if writer_kind == 'mindgrasp':        # the project's recorder (mindgrasp bag record)
        from mindgrasp_bag.writer import BagWriter

        with BagWriter(path) as writer:
            for topic, typ in topics:
                writer.add_topic(topic, typ)
            for ns, topic, typ, m in msgs:
                writer.write(topic, ns, store.serialize_cdr(m, typ))
        return path
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conns = {topic: writer.add_connection(topic, typ, typestore=store)
                 for topic, typ in topics}
        for ns, topic, typ, m in msgs:
            writer.write(conns[topic], ns, store.serialize_cdr(m, typ))
    return path


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('bags')
    train_rec = make_recording(trials_per_class=6, seed=0)
    test_rec = make_recording(trials_per_class=3, seed=5)
    return (write_run_bag(root / 'train_run', train_rec), train_rec,
            write_run_bag(root / 'test_run', test_rec), test_rec)


def test_load_bag_recovers_data_and_cues(bags):
    path, rec, _, _ = bags
    loaded = load_bag(path)
    assert loaded.rate == RATE and loaded.channels == rec.channels
    assert loaded.first_sample_index == 1000
    np.testing.assert_array_equal(loaded.events, rec.events)
    gap = slice(40 * 4, 42 * 4)
    assert np.isnan(loaded.data[gap]).all()
    ok = np.ones(len(rec.data), bool)
    ok[gap] = False
    np.testing.assert_allclose(loaded.data[ok], rec.data[ok], rtol=1e-6)


def test_load_bag_written_by_the_project_recorder(tmp_path):
    rec = make_recording(trials_per_class=1, seed=2)
    loaded = load_bag(write_run_bag(tmp_path / 'rec', rec, drop=(), writer_kind='mindgrasp'))
    np.testing.assert_array_equal(loaded.events, rec.events)
    np.testing.assert_allclose(loaded.data, rec.data, rtol=1e-6)


def test_load_bag_errors(tmp_path, bags):
    with pytest.raises(ClassifierError, match='does not exist'):
        load_bag(tmp_path / 'nothing')
    (tmp_path / 'empty').mkdir()
    with pytest.raises(ClassifierError, match=r'holds no rosbag2 \(no metadata.yaml\)'):
        load_bag(tmp_path / 'empty')
    with pytest.raises(ClassifierError, match="has no /eeg/other topic"):
        load_bag(bags[0], eeg_topic='/eeg/other')


def test_event_map_parsing():
    assert parse_event_map('T1=left_hand, T2=right_hand') == {'T1': 0, 'T2': 1}
    assert parse_event_map('769=0,770=1,771=both_feet') == {'769': 0, '770': 1, '771': 3}
    with pytest.raises(ClassifierError, match="Unknown decoder class 'elbow'"):
        parse_event_map('T1=elbow')
    with pytest.raises(ClassifierError, match='has no "="'):
        parse_event_map('T1')


def _mindgrasp(*args):
    return subprocess.run([sys.executable, '-m', 'mindgrasp_cli', *args],
                          capture_output=True, text=True, timeout=300)


@pytest.mark.slow
def test_train_and_evaluate_commands_on_bags(tmp_path, bags):
    train_bag, _, test_bag, _ = bags
    out = _mindgrasp('train', 'classifier', '--bag', str(train_bag), '--channels', 'all',
                     '-o', str(tmp_path / 'm'), '--cv', '3')
    assert out.returncode == 0, out.stderr
    assert 'Cross-validation (3 folds' in out.stdout and 'confusion' in out.stdout
    assert (tmp_path / 'm.json').is_file() and (tmp_path / 'm.npz').is_file()
    res = _mindgrasp('evaluate', 'classifier', '--model', str(tmp_path / 'm.json'), '--bag',
                     str(test_bag), '--json')
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout.strip().splitlines()[-1])
    for key in ('accuracy', 'balanced_accuracy', 'n_trials', 'confusion', 'classes'):
        assert key in report
    assert report['n_trials'] == 12 and report['accuracy'] >= 0.9
    assert 'certainty per true class' in res.stdout
    bad = _mindgrasp('evaluate', 'classifier', '--model', str(tmp_path / 'x.json'), '--bag',
                     str(test_bag))
    assert bad.returncode == 1 and 'does not exist; train one' in bad.stderr


@pytest.mark.slow
def test_train_command_reports_too_few_trials(tmp_path):
    rec = make_recording(classes=(0, 1), trials_per_class=2, seed=0)
    path = write_run_bag(tmp_path / 'short_run', rec)
    out = _mindgrasp('train', 'classifier', '--bag', str(path), '--channels', 'all',
                     '-o', str(tmp_path / 'm'))
    assert out.returncode == 1
    assert "Too few trials per class to train: {'left_hand': 2, 'right_hand': 2}" in out.stderr


def test_aborted_trials_are_left_out_unless_kept(tmp_path):
    rec = make_recording(trials_per_class=2, seed=3)
    path = write_run_bag(tmp_path / 'run', rec, drop=(), abort=(2, 5))
    loaded = load_bag(path)
    assert loaded.n_aborted == 2
    keep = [i for i in range(len(rec.events)) if i + 1 not in (2, 5)]
    np.testing.assert_array_equal(loaded.events, rec.events[keep])
    kept = load_bag(path, keep_aborted=True)
    assert kept.n_aborted == 2
    np.testing.assert_array_equal(kept.events, rec.events)


def test_intent_labels_tile_each_intent():
    changes = [(0.0, 'rest'), (1.0, 'left_hand'), (6.2, 'both_feet'), (7.0, 'rest')]
    assert intent_events(changes, 10.0, 0.5, 2.5) == [(1.0, 0), (3.0, 0)]
    assert intent_events(changes, 10.0, 0.0, 0.5) == [
        (1.0, 0), (1.5, 0), (2.0, 0), (2.5, 0), (3.0, 0), (3.5, 0), (4.0, 0), (4.5, 0),
        (5.0, 0), (5.5, 0), (6.2, 3)]
    with pytest.raises(ClassifierError, match='--labels must be one of prompt, intent, markers'):
        load_bag('x', labels='cue')
    with pytest.raises(ClassifierError, match='--labels markers needs --event-map'):
        load_bag('x', labels='markers')


@pytest.mark.slow
def test_train_leaves_out_aborted_trials_and_reads_intent_labels(tmp_path):
    rec = make_recording(trials_per_class=6, seed=0)
    path = write_run_bag(tmp_path / 'run', rec, abort=(1, 7, 9), intent=True)
    out = _mindgrasp('train', 'classifier', '--bag', str(path), '--channels', 'all',
                     '-o', str(tmp_path / 'm'), '--cv', '0', '--min-trials', '3')
    assert out.returncode == 0, out.stderr
    assert 'Left out 3 aborted trial(s) (cut short by a robot reset); --keep-aborted keeps them.' \
        in out.stdout
    kept = _mindgrasp('train', 'classifier', '--bag', str(path), '--channels', 'all',
                      '-o', str(tmp_path / 'k'), '--cv', '0', '--keep-aborted', '--min-trials', '3')
    assert kept.returncode == 0 and 'Kept 3 aborted trial(s)' in kept.stdout, kept.stderr
    # a demo/experiment run: the subject's intent labels the EEG, in training and evaluation
    model = tmp_path / 'intent'
    out = _mindgrasp('train', 'classifier', '--bag', str(path), '--channels', 'all',
                     '-o', str(model), '--cv', '0', '--labels', 'intent')
    assert out.returncode == 0, out.stderr
    res = _mindgrasp('evaluate', 'classifier', '--model', f'{model}.json', '--bag', str(path),
                     '--labels', 'intent', '--json')
    assert res.returncode == 0, res.stderr
    report = json.loads(res.stdout.strip().splitlines()[-1])
    assert report['n_trials'] == 24 and report['accuracy'] >= 0.9
    no_intent = write_run_bag(tmp_path / 'graz', rec)
    bad = _mindgrasp('evaluate', 'classifier', '--model', f'{model}.json', '--bag',
                     str(no_intent), '--labels', 'intent')
    assert bad.returncode == 1
    assert 'has no /virtual_subject/intent topic, so --labels intent' in bad.stderr
