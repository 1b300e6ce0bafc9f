"""The bag recorder in lock-step: the in-process graph answers its discovery, raw subscriptions get
CDR bytes, and ``mindgrasp launch <profile> --lockstep`` writes ``<run dir>/bag`` on sim time."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from mcap.reader import make_reader

from mindgrasp_bag import BagReader
from mindgrasp_launch.run_extras import DEFAULT_RECORD_EXCLUDE
from mindgrasp_trainer.graz import GrazProtocol

# short Graz timing: 2 trials take ~5 simulated seconds; a few /trainer/display frames, which
# the default record_exclude_regex leaves out of the bag
GRAZ_PARAMS = {'graz_prompter': {'ros__parameters': {
    'fixation': 0.3, 'cue': 0.5, 'imagery': 0.5, 'rest_min': 0.2, 'rest_max': 0.2,
    'start_delay': 1.0, 'display_rate': 2.0}}}


def test_intra_graph_and_raw_subscriptions_in_lockstep() -> None:
    from mindgrasp_ros.interfaces.std_msgs.msg import String

    from mindgrasp_ros import graph, rclpy
    from mindgrasp_ros.typesupport import serialize

    got: list[bytes] = []
    qos = rclpy.qos.QoSProfile(depth=5, reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT)

    class Talker(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('talker', namespace='/ns', **kwargs)
            self.pub = self.create_publisher(String, '/chatter', qos)

    class Listener(rclpy.node.Node):
        def __init__(self, **kwargs: object) -> None:
            super().__init__('listener', **kwargs)
            self.create_subscription(String, '/chatter', got.append, qos, raw=True)

    with graph.LockstepRunner() as runner:
        talker = runner.add(Talker)
        listener = runner.add(Listener)
        assert ('/chatter', ['std_msgs/msg/String']) in listener.get_topic_names_and_types()
        assert ('talker', '/ns') in listener.get_node_names_and_namespaces()
        (info,) = listener.get_publishers_info_by_topic('/chatter')
        assert (info.node_name, info.node_namespace, info.topic_type) == (
            'talker', '/ns', 'std_msgs/msg/String')
        assert info.qos_profile.reliability == rclpy.qos.ReliabilityPolicy.BEST_EFFORT
        assert listener.count_subscribers('/chatter') == 1
        msg = String(data='first')
        talker.pub.publish(msg)
        msg.data = 'changed after publishing'     # the bytes are the message as published
        runner.step(0.01)
    assert got == [serialize(String(data='first'), 'std_msgs/msg/String')]


def test_lockstep_components_compose_the_launchs_recorder(tmp_path: Path) -> None:
    """The recorder of a live launch (same topics argument), writing the given bag; none without
    a bag (the experiments) or with record:=false."""
    from mindgrasp_bag.recorder_node import RecorderNode
    from mindgrasp_launch.lockstep import lockstep_components

    def recorders(args: dict, bag: Path | None) -> list:
        comps = lockstep_components('graz', args, tmp_path / 'params', bag=bag)
        found = [c for c in comps if c.module == RecorderNode.__module__]
        assert comps[len(comps) - len(found):] == found            # composed last
        return found

    (rec,) = recorders({'record_topics': '/eeg/raw /trainer/prompt'}, tmp_path / 'bag')
    assert rec.parameters['output'] == str(tmp_path / 'bag')
    assert rec.parameters['topics'] == ['/eeg/raw', '/trainer/prompt']
    # the runner's /clock beside the launch's exclusions (default: the display frames)
    assert rec.parameters['exclude_regex'] == f'^/clock$|{DEFAULT_RECORD_EXCLUDE}'
    assert rec.parameters['compression'] == 'zstd'
    (rec,) = recorders({'record_exclude_regex': ''}, tmp_path / 'bag')
    assert rec.parameters['exclude_regex'] == '^/clock$'
    assert recorders({}, None) == []
    assert recorders({'record': 'false'}, tmp_path / 'bag') == []


def test_lockstep_refuses_an_lsl_amplifier_with_one_line(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'graz', 'amp:=lsl',
         'eeg_stream:=MyAmp', '--lockstep', '--run-dir', str(tmp_path / 'run')],
        capture_output=True, text=True, timeout=300, check=False)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        'mindgrasp launch: error: lock-step cannot take EEG from an LSL stream: LSL runs on wall '
        'time, so the acquisition node is left out, and this launch has no virtual amplifier to '
        'publish /eeg/raw on simulated time. Start one (amp:=virtual; virtual_amp:=true in the '
        'eeg profile), or launch without --lockstep.']
    assert not (tmp_path / 'run').exists()       # refused before anything is created


def launch_graz(run_dir: Path, params_file: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, MINDGRASP_PARAMS_FILES=str(params_file))
    return subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'graz', 'trials:=2', 'seed:=5',
         '--lockstep', '--run-dir', str(run_dir)],
        capture_output=True, text=True, timeout=600, env=env, check=False)


@pytest.mark.timeout(900)
def test_lockstep_launch_records_a_bag_on_sim_time(tmp_path: Path) -> None:
    params = tmp_path / 'graz.yaml'
    params.write_text(yaml.safe_dump(GRAZ_PARAMS), encoding='utf-8')
    runs = []
    for name in ('a', 'b'):
        result = launch_graz(tmp_path / name, params)
        assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
        runs.append(tmp_path / name / 'bag')
    info = subprocess.run([sys.executable, '-m', 'mindgrasp_cli', 'bag', 'info',
                           str(runs[0])], capture_output=True, text=True, timeout=300,
                          check=False)
    assert info.returncode == 0, info.stderr
    for topic in ('/eeg/raw', '/trainer/prompt', '/virtual_subject/intent'):
        assert topic in info.stdout
    assert '/clock' not in info.stdout and '/trainer/display' not in info.stdout
    # record_compression defaults to zstd: every chunk of the MCAP file is compressed
    (mcap_file,) = runs[0].glob('*.mcap')
    with mcap_file.open('rb') as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.chunk_indexes
    assert {c.compression for c in summary.chunk_indexes} == {'zstd'}
    recorded = []
    for bag in runs:
        with BagReader(bag) as reader:
            recorded.append(list(reader.messages()))
    stamps = [t for _topic, t, _data in recorded[0]]
    # simulated time from 0: the whole run lies within its ~5 simulated seconds
    assert min(stamps) > 0 and max(stamps) < 20e9
    prompts = [t for topic, t, _data in recorded[0] if topic == '/trainer/prompt']
    timing = GRAZ_PARAMS['graz_prompter']['ros__parameters']
    schedule = GrazProtocol(n_trials=2, seed=5, **{k: v for k, v in timing.items()
                                                   if k != 'display_rate'}).schedule()
    assert len(prompts) == len(schedule)     # every prompt, recorded at its simulated onset
    assert [round((t - prompts[0]) * 1e-9, 2) for t in prompts] == [
        round(e.onset - schedule[0].onset, 2) for e in schedule]
    # the same seed: the same messages at the same simulated times
    assert recorded[0] == recorded[1]


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_trainer_profile_in_lockstep_records_its_session(tmp_path: Path) -> None:
    """The Trainer profile (simulator with the training robot, EEG, classifier, vision,
    controller, trainer) composed on simulated time: the trainer ends the launch, and the bag has
    what training reads (EEG and prompts) and the robots' poses."""
    from mindgrasp_ros.typesupport import typestore

    run_dir = tmp_path / 'run'
    result = subprocess.run(
        [sys.executable, '-m', 'mindgrasp_cli', 'launch', 'trainer', 'trials:=2', 'seed:=1',
         '--lockstep', '--run-dir', str(run_dir)],
        capture_output=True, text=True, timeout=800, check=False)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    store = typestore()
    with BagReader(run_dir / 'bag') as reader:
        assert {'/eeg/raw', '/bci/prediction', '/trainer_robot/ee_pose', '/ee_pose'} <= set(
            reader.topics)
        phases = [store.deserialize_cdr(data, 'mindgrasp_msgs/msg/Prompt').phase
                  for _topic, _t, data in reader.messages(['/trainer/prompt'])]
        assert reader.end_ns < 300e9          # simulated time from 0
    assert phases.count('move') == 2 and phases[-1] == 'end'
