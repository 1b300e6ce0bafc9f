"""The LSL marker node (``lsl_markers``) in its own process: events published over DDS come out of
an LSL marker stream (type Markers, one string channel, irregular rate, stable source_id), each
stamped with the LSL time at which it happened; and the launch profiles start it where a display
shows the participant something."""

from __future__ import annotations

import time

import pylsl
import pytest

from mindgrasp_eeg.event_markers import lsl_time
from mindgrasp_launch import LaunchService


def test_lsl_time_moves_an_event_to_the_lsl_clock() -> None:
    # an event 0.25 s old on the ROS clock is 0.25 s old on the LSL clock
    assert lsl_time(10_000_000_000, 10_250_000_000, 500.0) == pytest.approx(499.75)


@pytest.mark.parametrize(('args', 'cues'), [
    ([], None),                                              # no display: nothing to mirror
    (['markers:=true'], '/trainer/prompt'),
    (['display:=headless'], '/display/flip'),                # auto: the flips the participant saw
    (['display:=headless', 'markers:=false'], None),
])
def test_the_graz_profile_starts_the_marker_node_where_a_display_runs(args, cues) -> None:
    plan = LaunchService('graz', args).plan(strict=False)
    nodes = [p for p in plan.processes if p.label == 'lsl_markers']
    assert len(nodes) == (cues is not None)
    if cues:
        assert nodes[0].parameters['cue_topic'] == cues


def test_events_reach_the_marker_stream_at_their_time(spawn_node, rclpy_ctx, stream_name) -> None:
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import FsmState, Prompt, TaskTarget

    rclpy = rclpy_ctx
    node = rclpy.node.Node('marker_test')
    latched = rclpy.qos.QoSProfile(depth=10, reliability=rclpy.qos.ReliabilityPolicy.RELIABLE,
                                   durability=rclpy.qos.DurabilityPolicy.TRANSIENT_LOCAL)
    prompts = node.create_publisher(Prompt, '/trainer/prompt', latched)
    targets = node.create_publisher(TaskTarget, '/task/target', latched)
    states = node.create_publisher(FsmState, '/fsm/state', latched)
    mirror = spawn_node('mindgrasp_eeg.marker_node', stream_name=stream_name,
                        source_id=f'{stream_name}-id')
    found = pylsl.resolve_byprop('name', stream_name, 1, 60.0)
    assert found, mirror.output()
    info = found[0]
    assert (info.type(), info.channel_count(), info.nominal_srate(), info.source_id()) == (
        'Markers', 1, pylsl.IRREGULAR_RATE, f'{stream_name}-id')
    assert info.channel_format() == pylsl.cf_string
    inlet = pylsl.StreamInlet(info, processing_flags=pylsl.proc_clocksync)
    inlet.open_stream(timeout=30.0)
    # a cue whose onset was 0.3 s ago: its marker carries the onset, not the time it was heard
    onset = node.get_clock().now().nanoseconds - 300_000_000
    lsl_onset = pylsl.local_clock() - 0.3
    cue = Prompt(paradigm='graz', class_index=1, class_name='right_hand', phase='cue', trial=1)
    cue.header.stamp.sec, cue.header.stamp.nanosec = divmod(onset, 1_000_000_000)
    prompts.publish(cue)
    targets.publish(TaskTarget(trial=1, object_id=4, colour='blue', shape='cylinder'))
    for state in (1, 1, 3):        # /fsm/state repeats a state: one marker per change
        states.publish(FsmState(state=state, state_name=f'S{state}'))
    got: list[tuple[float, str]] = []
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and len(got) < 4:
        values, stamps = inlet.pull_chunk(timeout=0.1)
        got += [(t, v[0]) for t, v in zip(stamps, values, strict=True)]
    texts = [m for _, m in got]
    assert sorted(texts) == sorted(['prompt/cue/right_hand', 'target/blue cylinder',
                                    'state/1 S1', 'state/3 S3']), (texts, mirror.output())
    (cue_time,) = [t for t, m in got if m.startswith('prompt/')]
    assert cue_time == pytest.approx(lsl_onset, abs=0.02)
    node.destroy_node()
