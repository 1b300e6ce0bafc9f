"""Bag files: rosbag2 layout, metadata.yaml v9, MCAP ros2 profile, readers of other tools."""

from __future__ import annotations

import shutil

import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader as RosbagsReader

from conftest_bag import EEG, IMAGE, JOINTS, STRING, eeg_chunk, image, joints, string
from mindgrasp_bag import BagError, BagReader, BagWriter
from mindgrasp_bag.metadata import rebuild_metadata
from mindgrasp_bag.typestore import typestore

QOS_SENSOR = {'history': 'keep_last', 'depth': 5, 'reliability': 'best_effort',
              'durability': 'volatile'}
QOS_LATCHED = {'history': 'keep_last', 'depth': 1, 'reliability': 'reliable',
               'durability': 'transient_local'}


def _messages(n: int = 20) -> list[tuple[str, str, int, bytes]]:
    t0 = 1_700_000_000_000_000_000
    out = []
    for i in range(n):
        out.append(('/eeg/raw', EEG, t0 + i * 100_000_000, eeg_chunk(25 * i)))
        out.append(('/camera/color/image_raw', IMAGE, t0 + i * 100_000_000 + 1_000, image(i)))
        out.append(('/joint_states', JOINTS, t0 + i * 100_000_000 + 2_000, joints(i)))
    out.append(('/fsm/state_text', STRING, t0 + n * 100_000_000, string('done')))
    return out


def _write(path, messages, **kwargs):
    with BagWriter(path, **kwargs) as writer:
        qos = {'/camera/color/image_raw': [QOS_SENSOR], '/fsm/state_text': [QOS_LATCHED]}
        for topic, msgtype, _, _ in messages:
            writer.add_topic(topic, msgtype, offered_qos_profiles=qos.get(topic, []))
        for topic, _, stamp, data in messages:
            writer.write(topic, stamp, data)
    return path


def test_layout_and_metadata_follow_rosbag2_jazzy(tmp_path):
    messages = _messages()
    bag = _write(tmp_path / 'run', messages)
    assert sorted(p.name for p in bag.iterdir()) == ['metadata.yaml', 'run_0.mcap']
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['version'] == 9
    assert info['storage_identifier'] == 'mcap'
    assert info['relative_file_paths'] == ['run_0.mcap']
    assert info['message_count'] == len(messages)
    assert info['starting_time']['nanoseconds_since_epoch'] == messages[0][2]
    assert info['duration']['nanoseconds'] == messages[-1][2] - messages[0][2]
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    image_meta = topics['/camera/color/image_raw']['topic_metadata']
    assert image_meta['type'] == IMAGE
    assert image_meta['serialization_format'] == 'cdr'
    assert image_meta['type_description_hash'] == typestore().hash_rihs01(IMAGE)
    assert image_meta['offered_qos_profiles'][0]['reliability'] == 'best_effort'
    assert image_meta['offered_qos_profiles'][0]['depth'] == 5
    assert topics['/eeg/raw']['message_count'] == 20


def test_mcap_has_ros2_profile_full_definitions_and_qos(tmp_path):
    bag = _write(tmp_path / 'run', _messages(3))
    with (bag / 'run_0.mcap').open('rb') as f:
        reader = make_reader(f)
        assert reader.get_header().profile == 'ros2'
        summary = reader.get_summary()
        schemas = {s.name: s for s in summary.schemas.values()}
        assert {s.encoding for s in schemas.values()} == {'ros2msg'}
        assert schemas[EEG].data.decode() == typestore().generate_msgdef(EEG, ros_version=2)[0]
        assert b'MSG: std_msgs/Header' in schemas[EEG].data
        channels = {c.topic: c for c in summary.channels.values()}
        assert {c.message_encoding for c in channels.values()} == {'cdr'}
        latched = yaml.safe_load(channels['/fsm/state_text'].metadata['offered_qos_profiles'])
        assert latched[0]['durability'] == 'transient_local'
        assert channels['/eeg/raw'].metadata['topic_type_hash'].startswith('RIHS01_')
        stored = {m.name: m.metadata for m in reader.iter_metadata()}
        assert 'serialized_metadata' in stored['rosbag2']


def test_our_bag_decodes_with_mcap_ros2_and_reads_with_rosbags(tmp_path):
    messages = _messages(5)
    bag = _write(tmp_path / 'run', messages, compression='zstd')
    with (bag / 'run_0.mcap').open('rb') as f:
        decoded = [(c.topic, m) for _, c, _, m in make_reader(
            f, decoder_factories=[DecoderFactory()]).iter_decoded_messages()]
    eeg = [m for topic, m in decoded if topic == '/eeg/raw']
    assert len(eeg) == 5 and eeg[2].first_sample_index == 50 and eeg[2].n_samples == 25
    assert len(eeg[2].data) == 25 * 32 and eeg[2].channel_names[31] == 'C31'
    assert next(m for t, m in decoded if t == '/fsm/state_text').data == 'done'
    with RosbagsReader(bag) as reader:
        got = [(c.topic, t, bytes(d)) for c, t, d in reader.messages()]
    assert got == [(topic, stamp, data) for topic, _, stamp, data in messages]


def test_round_trip_identical_bytes_and_order(tmp_path):
    messages = _messages()
    bag = _write(tmp_path / 'run', messages)
    with BagReader(bag) as reader:
        assert reader.storage == 'mcap' and reader.complete
        assert reader.message_count == len(messages)
        assert reader.topics['/eeg/raw'].type == EEG
        assert reader.topics['/camera/color/image_raw'].offered_qos_profiles[0]['depth'] == 5
        got = list(reader.messages())
    assert got == [(topic, stamp, data) for topic, _, stamp, data in messages]


@pytest.mark.parametrize('split', [{'max_bag_size': 20_000}, {'max_bag_duration': 0.5}])
def test_split_by_size_or_duration(tmp_path, split):
    messages = _messages(30)
    bag = _write(tmp_path / 'run', messages, chunk_size=4096, **split)
    files = sorted(p.name for p in bag.glob('*.mcap'))
    assert len(files) > 2
    info = yaml.safe_load((bag / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['relative_file_paths'] == [f'run_{i}.mcap' for i in range(len(files))]
    assert sum(f['message_count'] for f in info['files']) == len(messages)
    with RosbagsReader(bag) as reader:
        assert [bytes(d) for _, _, d in reader.messages()] == [m[3] for m in messages]
    with BagReader(bag) as reader:
        assert [d for _, _, d in reader.messages()] == [m[3] for m in messages]


def test_missing_metadata_is_rebuilt_from_summary_and_by_scan(tmp_path):
    messages = _messages(10)
    bag = _write(tmp_path / 'run', messages, max_bag_duration=0.4)
    original = yaml.safe_load((bag / 'metadata.yaml').read_text())
    (bag / 'metadata.yaml').unlink()
    rebuilt = rebuild_metadata(bag)
    a, b = original['rosbag2_bagfile_information'], rebuilt['rosbag2_bagfile_information']
    for key in ('version', 'message_count', 'duration', 'starting_time', 'relative_file_paths',
                'files', 'topics_with_message_count'):
        assert a[key] == b[key], key
    # Unfinished file (no summary): the same counts from a scan.
    last = sorted(bag.glob('*.mcap'))[-1]
    data = last.read_bytes()
    last.write_bytes(data[:-200])   # summary and footer gone
    (bag / 'metadata.yaml').unlink()
    with BagReader(bag) as reader:
        assert not reader.complete and any('not closed' in n for n in reader.notes)
        assert reader.message_count == len(list(reader.messages()))


def test_truncated_file_recovers_every_complete_chunk(tmp_path):
    messages = _messages(40)
    bag = tmp_path / 'run'
    writer = BagWriter(bag, chunk_size=1 << 30, flush_interval=3600)
    writer.open()
    for topic, msgtype, _, _ in messages:
        writer.add_topic(topic, msgtype)
    for k, (topic, _, stamp, data) in enumerate(messages):
        writer.write(topic, stamp, data)
        if k % 10 == 9:
            writer.flush()   # a chunk every 10 messages
    writer.flush()
    size_after_flush = (bag / 'run_0.mcap').stat().st_size
    writer.abort()          # like a kill: no summary, no footer
    path = bag / 'run_0.mcap'
    full = path.read_bytes()
    assert len(full) == size_after_flush
    # Cut inside the last chunk: the messages of all earlier chunks remain.
    path.write_bytes(full[:-50])
    (bag / 'metadata.yaml').unlink(missing_ok=True)
    with BagReader(bag) as reader:
        got = list(reader.messages())
        assert any('cut off' in n for n in reader.notes)
    n_complete = len(messages) // 10 * 10   # 121 messages: the last chunk holds one, cut off
    assert got == [(t, s, d) for t, _, s, d in messages[:n_complete]]


def test_rosbags_written_bags_are_read_sqlite3_and_mcap(tmp_path):
    from rosbags.rosbag2 import StoragePlugin

    from conftest_bag import write_rosbags_bag

    messages = _messages(5)
    for storage in (StoragePlugin.SQLITE3, StoragePlugin.MCAP):
        bag = write_rosbags_bag(tmp_path / storage.name, messages, storage)
        with BagReader(bag) as reader:
            assert reader.storage == storage.name.lower()
            assert reader.topics['/joint_states'].type == JOINTS
            assert [(t, s, d) for t, s, d in reader.messages()] == \
                [(t, s, d) for t, _, s, d in messages]


def test_writer_refuses_bad_use_with_clear_messages(tmp_path):
    bag = _write(tmp_path / 'run', _messages(1))
    with pytest.raises(BagError, match='exists already; choose another output path'):
        BagWriter(bag).open()
    with pytest.raises(BagError, match="compression 'gzip' is not supported"):
        BagWriter(tmp_path / 'x', compression='gzip')
    with BagWriter(tmp_path / 'y') as writer:
        with pytest.raises(BagError, match='not in the type store'):
            writer.add_topic('/a', 'foo_msgs/msg/Unknown')
        with pytest.raises(BagError, match='was not added to the bag; call add_topic'):
            writer.write('/b', 1, b'')
        writer.add_topic('/a', STRING)
        with pytest.raises(BagError, match='cannot also be recorded as'):
            writer.add_topic('/a', JOINTS)
    with pytest.raises(BagError, match='is not open; call open'):
        BagWriter(tmp_path / 'z').write('/a', 1, b'')


def test_missing_and_corrupt_bags_give_clear_errors(tmp_path):
    with pytest.raises(BagError, match='does not exist; pass the path of a bag directory'):
        BagReader(tmp_path / 'nope').open()
    (tmp_path / 'empty').mkdir()
    with pytest.raises(BagError, match='is not a rosbag2 bag'):
        BagReader(tmp_path / 'empty').open()
    garbage = tmp_path / 'garbage'
    garbage.mkdir()
    (garbage / 'garbage_0.mcap').write_bytes(b'not an mcap file at all' * 10)
    with pytest.raises(BagError, match='is not an MCAP file'):
        BagReader(garbage).open()
    bag = _write(tmp_path / 'run', _messages(2))
    (bag / 'metadata.yaml').write_text('rosbag2_bagfile_information: {version: 9, storage_identi')
    with BagReader(bag) as reader:       # read what can be read: the files, without it
        # said as corrupt (not as missing), with the fix
        corrupt = [n for n in reader.notes if 'metadata.yaml' in n]
        assert len(corrupt) == 1 and 'is corrupt (not valid YAML at line 1)' in corrupt[0]
        assert f'run `mindgrasp bag reindex {bag}`' in corrupt[0]
        assert 'is missing' not in corrupt[0] and 'read without it' in corrupt[0]
        assert len(list(reader.messages())) == reader.message_count > 0
    bag2 = shutil.copytree(tmp_path / 'run', tmp_path / 'run2')
    (bag2 / 'run_0.mcap').unlink()
    with pytest.raises(BagError, match=r'is not a rosbag2 bag|cannot be read'):
        BagReader(bag2).open()
