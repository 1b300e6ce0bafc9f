"""An amplifier's LSL marker stream on record (issue 30): a real pylsl EEG outlet with its marker
stream in one process, the acquisition node (``marker_stream:=auto``) and the bag recorder in
others, over real DDS; the markers line up with their EEG samples on /eeg/markers, in the bag,
in its replay and in the BIDS export's events."""

from __future__ import annotations

import csv
import time
from pathlib import Path

import numpy as np
import pytest

from mindgrasp_eeg.marker_inlet import marker_stream_name

pytestmark = pytest.mark.slow
RATE = 250.0


class MarkerListener:
    """A test node collecting /eeg/raw and /eeg/markers."""

    def __init__(self, rclpy) -> None:
        from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, EEGMarker

        from mindgrasp_ros.topics import EEG_MARKERS, EEG_RAW

        self.node = rclpy.node.Node('marker_test_listener')
        self.executor = rclpy.executors.SingleThreadedExecutor()
        self.executor.add_node(self.node)
        self.chunks: list[object] = []
        self.markers: list[object] = []
        self.node.create_subscription(EEGChunk, EEG_RAW.name, self.chunks.append, EEG_RAW.qos)
        self.node.create_subscription(EEGMarker, EEG_MARKERS.name, self.markers.append,
                                      EEG_MARKERS.qos)

    def spin_until(self, until, seconds: float = 60.0) -> bool:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.executor.spin_once(timeout_sec=0.02)
            if until():
                return True
        return until()


def _ns(stamp) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def spike_stamps_ns(chunks: list[object], n_channels: int) -> list[int]:
    """ROS time (ns) of every sample whose channel 0 carries the source's 1 mV spike."""
    out = []
    for msg in chunks:
        data = np.asarray(msg.data).reshape(msg.n_samples, n_channels)
        for i in np.flatnonzero(data[:, 0] > 0.5e-3):
            out.append(_ns(msg.header.stamp) + round(i / msg.sample_rate * 1e9))
    return out


def test_marker_stream_name() -> None:
    assert marker_stream_name('none', 'Amp') is None
    assert marker_stream_name('', 'Amp') is None
    assert marker_stream_name('auto', 'Amp') == 'Amp-markers'
    assert marker_stream_name('StimPC', 'Amp') == 'StimPC'


def test_amplifier_markers_relayed_recorded_and_exported(
        spawn_node, lsl_source, rclpy_ctx, stream_name, tmp_path: Path) -> None:
    from mindgrasp_eeg.bids import export_bids
    from mindgrasp_eeg.export import read_session

    n_ch = 4
    bag = tmp_path / 'bag'
    recorder = spawn_node('mindgrasp_cli', 'bag', 'record', '-o', str(bag), '/eeg/raw',
                          '/eeg/markers')
    # once the node's inlet is connected, markers every 0.5 s of samples; the marker stream
    # closes after 2 s of them, the EEG goes on
    lsl_source(stream_name, '--n-channels', str(n_ch), '--duration', '120',
               '--markers-every', '0.5', '--markers-until', '2')
    acq = spawn_node('mindgrasp_eeg.acquisition_node', stream_name=stream_name,
                     n_channels=n_ch, check_channel_names=False, marker_stream='auto')
    listener = MarkerListener(rclpy_ctx)
    try:
        assert listener.spin_until(lambda: len(listener.markers) >= 3), acq.output()
        # the stream's end is one line, and the EEG goes on (no crash, no exit)
        lost = f"marker stream '{stream_name}-markers' is lost"
        assert acq.wait_for_output(lost, 60), acq.output()
        n = len(listener.chunks)
        assert listener.spin_until(lambda: len(listener.chunks) > n + 10), acq.output()
        assert acq.poll() is None, acq.output()
        assert recorder.wait_for_output('Subscribed to /eeg/markers', 60), recorder.output()
        # the recorder got the latched history (transient local, depth 100) once subscribed
        assert recorder.wait_for_output('Subscribed to /eeg/raw', 60), recorder.output()
    finally:
        listener.node.destroy_node()
    assert recorder.stop(timeout=30) == 0, recorder.output()
    assert acq.output().count(lost) == 1, acq.output()
    assert 'Traceback' not in acq.output()

    # each marker's ROS stamp is its EEG sample's (same LSL-to-ROS mapping), within 2 ms
    spikes = np.array(spike_stamps_ns(listener.chunks, n_ch))
    marker = listener.markers[0]
    assert marker.stream_name == f'{stream_name}-markers' and marker.data.startswith('S')
    matched = 0
    for m in listener.markers:
        if len(spikes):
            err = np.min(np.abs(spikes - _ns(m.header.stamp))) * 1e-9
            if err < 0.25:                    # the spike's chunk was received
                assert err < 2e-3, (m.data, err)
                matched += 1
    assert matched >= 2, (len(listener.markers), len(spikes))

    # the bag holds them; the export's annotations and the BIDS events have them at their sample
    recording = read_session(bag)
    anns = [(on, desc) for on, _d, desc in recording.annotations if desc.startswith('S')]
    assert len(anns) >= 2, recording.annotations
    data = recording.data
    for on, desc in anns:
        k = round(on * RATE)
        if 0 <= k < len(data) and np.isfinite(data[k, 0]):
            window = data[max(0, k - 1):k + 2, 0]
            assert np.nanmax(window) > 0.5e-3, (desc, on)     # the spike is at the marker
    # a replay of the bag publishes them again, stamps and all
    replayed = MarkerListener(rclpy_ctx)
    try:
        spawn_node('mindgrasp_cli', 'bag', 'play', str(bag), '--topics', '/eeg/markers',
                   '--no-progress')
        recorded = {(m.data, _ns(m.header.stamp)) for m in listener.markers}
        assert replayed.spin_until(lambda: len(replayed.markers) >= len(anns)), anns
        assert {(m.data, _ns(m.header.stamp)) for m in replayed.markers} <= recorded
    finally:
        replayed.node.destroy_node()
    root = tmp_path / 'bids'
    export_bids([bag], root, 'M01')
    events = next(root.glob('sub-M01/eeg/*_events.tsv'))
    with events.open(encoding='utf-8') as f:
        types = {row['trial_type'] for row in csv.DictReader(f, delimiter='\t')}
    assert {desc for _on, desc in anns} <= types, types


def test_bad_marker_stream_name_is_one_line(spawn_node, stream_name) -> None:
    acq = spawn_node('mindgrasp_eeg.acquisition_node', stream_name=stream_name,
                     marker_stream="it's")
    assert acq.wait(60) == 2, acq.output()
    out = acq.output()
    assert 'contains a quote' in out and 'Traceback' not in out, out
