"""EEG acquisition node: one LSL EEG stream -> mindgrasp_msgs/EEGChunk on /eeg/raw.

    python -m mindgrasp_eeg.acquisition_node --ros-args -p stream_name:=MyAmp
    python -m mindgrasp_eeg.acquisition_node --ros-args \
        --params-file config/param/eeg.yaml

Publishes ``/eeg/raw`` (sensor-data QoS, depth 100) as soon as samples arrive: a reader thread
blocks in the inlet until the amplifier's next block comes, pulls it whole, stamps it and hands
it to the executor through a guard condition, which publishes it (one chunk per block, in volts,
stamped with the ROS time of the first sample; see :mod:`mindgrasp_eeg.acquisition` for the
LSL-to-ROS time mapping). A timer pull every ``chunk_period`` added up to that period to every
sample's latency, and more when a loaded machine delayed the timer. ``/eeg/status``
(diagnostic_msgs/DiagnosticArray, reliable) goes out every ``status_period`` seconds and on every
change of level (checked every ``chunk_period``). All the work is done by
:class:`~mindgrasp_eeg.acquisition.EEGAcquisition`.

The stream is looked for in a background thread (up to ``resolve_timeout`` s): meanwhile the node
answers signals at once and says "Searching for the LSL stream ..." on /eeg/status (WARN). Not
found in time, or a layout that does not match: exit 1 with the reason.

Markers: with ``marker_stream:=auto`` (``<stream_name>-markers``, as ``mindgrasp eeg play`` names
it) or ``marker_stream:=NAME`` the node also relays an LSL marker stream (type ``Markers``: an
amplifier's triggers, a stimulus PC) to ``/eeg/markers`` (mindgrasp_msgs/EEGMarker), each stamped
on the same LSL-to-ROS mapping as the EEG samples, so the recorder keeps them and the exports read
them as events (:mod:`mindgrasp_eeg.marker_inlet`). Off by default; a marker stream not found or
lost is one log line, never an exit.

The amplifier's metadata (``<acquisition>`` manufacturer, model, reference; each channel's
label, unit and type) goes to ``$MINDGRASP_RUN_DIR/eeg_stream.json`` once connected
(:mod:`mindgrasp_eeg.stream_metadata`), for ``mindgrasp export bids``.

Which sender is trusted: by default any stream with the right name (a warning says so;
``allow_unpinned:=false`` refuses to start instead, as the hardware profile does). Pin the
amplifier with ``source_id`` and ``hostname`` (``hostname:=local`` means this host), so no other
sender on the network can stand in for it; the launch profiles that start the virtual amplifier
pin the node to it (a source id made per run). Whatever the selector, the first stream connected
to fixes the sender (source_id, host, LSL session): after a loss only that sender is taken back,
a stream of the same name from another host, source or session is refused (``refused_streams``
on /eeg/status, and the status names it).
"""

from __future__ import annotations

import os
import socket
import threading
from collections import deque
from pathlib import Path

import numpy as np
from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, EEGMarker

from mindgrasp_common.safe_files import DeferredWriter
from mindgrasp_eeg import EEGError
from mindgrasp_eeg.acquisition import (
    ERROR,
    OK,
    WARN,
    Chunk,
    EEGAcquisition,
    read_clocks,
    ros_stamp_ns,
)
from mindgrasp_eeg.marker_inlet import MarkerInlet, marker_stream_name
from mindgrasp_eeg.params import AcquisitionParams
from mindgrasp_eeg.ros_conversions import ns_to_time_fields
from mindgrasp_eeg.stream_metadata import write_stream_metadata
from mindgrasp_ros import rclpy
from mindgrasp_ros.logs import log_at
from mindgrasp_ros.node_main import end_after, fail, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import EEG_MARKERS, EEG_RAW, EEG_STATUS

_LEVELS = {OK: DiagnosticStatus.OK, WARN: DiagnosticStatus.WARN, ERROR: DiagnosticStatus.ERROR}
#: longest the reader thread blocks in one pull (s): how soon it sees a stop or a lost stream
_READ_WAIT = 0.1


class AcquisitionNode(rclpy.node.Node):
    """Wires :class:`EEGAcquisition` to ``/eeg/raw`` and ``/eeg/status``."""

    node_traits = NodeTraits(
        name='eeg_acquisition', provides=('eeg',),
        periodic={EEG_RAW.name: ('chunk_period', 'period')},
        lockstep_left_out='LSL runs on wall time; the virtual amplifier publishes /eeg/raw '
                          'itself in lock-step',
        lockstep_missing='lock-step cannot take EEG from an LSL stream: LSL runs on wall time, '
                         'so the acquisition node is left out, and this launch has no virtual '
                         'amplifier to publish /eeg/raw on simulated time. Start one '
                         '(amp:=virtual; virtual_amp:=true in the eeg profile), or launch '
                         'without --lockstep.')

    def __init__(self, **kwargs) -> None:
        super().__init__(self.node_traits.name, **kwargs)
        self.done = rclpy.task.Future()
        self.params = p = declare_params(self, AcquisitionParams)
        self.acq = EEGAcquisition(
            p.stream_name, p.stream_type, p.source_id, n_channels=p.n_channels,
            sample_rate=p.sample_rate,
            channel_names=p.channel_names if p.check_channel_names else (),
            adapt=p.adapt_to_stream, stream_unit=p.stream_unit, max_buflen=p.max_buflen,
            resolve_timeout=p.resolve_timeout, lost_timeout=p.lost_timeout,
            nan_policy=p.nan_policy, dejitter=p.dejitter, clocksync=p.clocksync,
            quality_window=p.quality_window, flat_threshold=p.flat_threshold,
            rail_threshold=p.rail_threshold,
            hostname=socket.gethostname() if p.hostname == 'local' else p.hostname)
        self.pub_raw = self.create_publisher(EEGChunk, EEG_RAW.name, EEG_RAW.qos)
        self.pub_status = self.create_publisher(DiagnosticArray, EEG_STATUS.name, EEG_STATUS.qos)
        markers = marker_stream_name(p.marker_stream, p.stream_name)
        self.markers = MarkerInlet(markers, clocksync=p.clocksync,
                                   resolve_timeout=p.resolve_timeout) if markers else None
        if self.markers is not None:
            self.pub_markers = self.create_publisher(EEGMarker, EEG_MARKERS.name,
                                                     EEG_MARKERS.qos)
            self.get_logger().info(f"Looking for the LSL marker stream '{markers}' (type "
                                   f'Markers) to relay to {EEG_MARKERS.name}.')
        self._wanted = (f'name {p.stream_name!r}, type {p.stream_type!r}, source_id '
                        f'{p.source_id!r}, host {self.acq.hostname!r}')
        if not self.acq.pinned and not p.allow_unpinned:
            msg = (f'The EEG stream {p.stream_name!r} is not pinned: set source_id and hostname '
                   '(hostname:=local for this host) to accept only your amplifier, or '
                   'allow_unpinned:=true to accept any sender of that name.')
            raise EEGError(msg)
        if not self.acq.pinned:
            self.get_logger().warning(
                'The EEG stream is not pinned: any LSL sender with this name is accepted. Set '
                'source_id and hostname (hostname:=local for this host) to accept only your '
                'amplifier.')
        self.get_logger().info(f'Searching for the LSL stream ({self._wanted}) for up to '
                               f'{p.resolve_timeout:g} s.')
        self._n_warnings = 0
        self._n_refusals = 0
        self._last_level = -1
        self._last_stamp_ns = -1
        self._outbox: deque[EEGChunk] = deque()        # reader thread -> executor
        self._ready = self.create_guard_condition(self.publish_callback)
        self._stop_reading = threading.Event()
        self._streaming = threading.Event()            # the search ended well: pull
        run_dir = os.environ.get('MINDGRASP_RUN_DIR', '')
        self._files = DeferredWriter(Path(run_dir)) if run_dir else None
        self.acq.start_search()
        self._reader = threading.Thread(target=self.read_loop, name='eeg-reader', daemon=True)
        self._reader.start()
        self.create_timer(p.chunk_period, self.poll_callback)
        self.create_timer(p.status_period, self.status_callback)
        end_after(self, p.duration)

    def _connected(self) -> bool:
        """False while the search goes on; raises EEGError when it failed (ends the node)."""
        if not self.acq.searching:
            return True
        desc = self.acq.finish_search()
        if desc is None:
            return False
        for warning in self.acq.warnings:
            self.get_logger().warning(warning)
        self._n_warnings = len(self.acq.warnings)
        self.get_logger().info(f'Connected to {desc.summary()}, unit {desc.unit or "?"} '
                               f'(x{self.acq.scale:g} to volts); publishing /eeg/raw as each '
                               'block arrives.')
        self.status_callback()
        self.record_metadata()
        self._streaming.set()
        return True

    def record_metadata(self) -> None:
        """Keep the amplifier's metadata (manufacturer, model, reference, channel units and
        types) in the run directory, ``$MINDGRASP_RUN_DIR/eeg_stream.json``, for the exports;
        nothing outside a launch. A full disk is one warning: the file is kept, retried at the
        node's end and else copied to the fallback folder the line names; the EEG still flows."""
        desc = self.acq.desc
        if self._files is None or desc is None:
            return
        run_dir = self._files.run_dir
        try:
            lines = self._files.write(run_dir, 'stream metadata',
                                      lambda directory: write_stream_metadata(desc, directory))
        except OSError as exc:   # not a disk fault (DeferredWriter keeps those): say it, go on
            lines = [f'Cannot keep the stream metadata in {run_dir} ({exc}); exports will use '
                     'their options.']
        for line in lines:
            self.get_logger().warning(line)
        if not self._files.pending:
            self.get_logger().info(f'Stream metadata kept in {run_dir / "eeg_stream.json"}.')

    def read_loop(self) -> None:
        """Reader thread: wake the executor when the search ends (it checks the stream and
        logs), then wait for each block, stamp it, queue it for :meth:`publish_callback`. It
        alone pulls from the inlet (and reconnects); an unexpected error is logged and the
        loop goes on, so the node never stops publishing silently."""
        wait = min(_READ_WAIT, self.params.lost_timeout / 2)
        while not self._stop_reading.is_set() and not self.acq.wait_search(wait):
            pass
        self._ready.trigger()
        while not self._stop_reading.is_set():
            if not self._streaming.wait(wait):
                continue
            try:
                chunks = self.acq.poll(timeout=wait)
                if not chunks:
                    continue
                # both clocks read right after the pull: a sample keeps its age
                lsl_now, ros_now = read_clocks(lambda: self.get_clock().now().nanoseconds)
                for chunk in chunks:
                    self._outbox.append(self.chunk_message(chunk, lsl_now, ros_now))
                self._ready.trigger()
            except Exception as exc:  # a dying reader would stop /eeg/raw without a word
                self.get_logger().error(f'Reading the LSL stream failed ({type(exc).__name__}: '
                                        f'{exc}); trying again.')
                self._stop_reading.wait(wait)

    def chunk_message(self, chunk: Chunk, lsl_now: float, ros_now: int) -> EEGChunk:
        """The EEGChunk of ``chunk`` (volts), stamped with its first sample's ROS time."""
        stamp = ros_stamp_ns(float(chunk.timestamps[0]), lsl_now, ros_now)
        stamp = max(stamp, self._last_stamp_ns + 1)   # never backwards
        self._last_stamp_ns = stamp
        desc = self.acq.desc
        msg = EEGChunk(sample_rate=desc.sample_rate, channel_names=list(desc.channel_names),
                       n_samples=len(chunk.data), first_sample_index=chunk.first_index,
                       unit='V', data=np.ascontiguousarray(chunk.data).ravel())
        msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_time_fields(stamp)
        msg.header.frame_id = self.params.frame_id
        return msg

    def publish_callback(self) -> None:
        """Publish the chunks the reader thread queued, oldest first (first, once the search
        ended: connect, or end the node when the stream was not found or does not fit)."""
        if self.acq.searching and not self.done.done():
            try:
                self._connected()
            except EEGError as exc:
                fail(self, str(exc))
                return
        while self._outbox:
            self.pub_raw.publish(self._outbox.popleft())

    def poll_callback(self) -> None:
        """Every ``chunk_period``: relay markers, finish the search (a stream not found or of
        the wrong layout ends the node with exit code 1 and the reason), log new warnings and
        level changes."""
        if self.done.done():
            return
        if self.markers is not None:
            self.relay_markers()
        try:
            connected = self._connected()
        except EEGError as exc:
            fail(self, str(exc))
            return
        if not connected:
            return
        while len(self.acq.refusals) > self._n_refusals:    # another sender's stream, refused
            self.get_logger().warning(self.acq.refusals[self._n_refusals] + '.')
            self._n_refusals += 1
        if len(self.acq.warnings) > self._n_warnings:
            for warning in self.acq.warnings[self._n_warnings:]:
                self.get_logger().warning(warning)
            self._n_warnings = len(self.acq.warnings)
        if self.acq.status().level != self._last_level:
            self.status_callback()

    def relay_markers(self) -> None:
        """Publish the markers that arrived on /eeg/markers, stamped as the EEG samples are;
        log the marker stream's news (found, not found yet, lost) one line each."""
        assert self.markers is not None
        markers, news = self.markers.poll()
        for level, line in news:
            log_at(self.get_logger(), level, line)
        if not markers:
            return
        lsl_now, ros_now = read_clocks(lambda: self.get_clock().now().nanoseconds)
        desc = self.markers.desc
        for marker in markers:
            msg = EEGMarker(data=marker.text, lsl_timestamp=marker.timestamp,
                            stream_name=desc.name if desc else '',
                            source_id=desc.source_id if desc else '')
            msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_time_fields(
                ros_stamp_ns(marker.timestamp, lsl_now, ros_now))
            msg.header.frame_id = self.params.frame_id
            self.pub_markers.publish(msg)

    def status_callback(self) -> None:
        """Publish /eeg/status; log level changes."""
        if self.acq.searching:
            item = DiagnosticStatus(level=DiagnosticStatus.WARN, name='eeg_acquisition',
                                    message=f'Searching for the LSL stream ({self._wanted}).',
                                    values=[KeyValue(key='state', value='searching')])
            msg = DiagnosticArray(status=[item])
            msg.header.stamp = self.get_clock().now().to_msg()
            self.pub_status.publish(msg)
            return
        status = self.acq.status()
        if status.level != self._last_level:
            log_at(self.get_logger(), {OK: 'info', WARN: 'warning', ERROR: 'error'}[status.level],
                   status.message)
            self._last_level = status.level
        desc = self.acq.desc
        item = DiagnosticStatus(level=_LEVELS[status.level], name='eeg_acquisition',
                                message=status.message,
                                hardware_id=desc.source_id if desc else '',
                                values=[KeyValue(key=k, value=v)
                                        for k, v in sorted(status.values.items())])
        msg = DiagnosticArray(status=[item])
        msg.header.stamp = self.get_clock().now().to_msg()
        self.pub_status.publish(msg)

    def destroy_node(self) -> None:
        """Stop the reader (it owns the inlet while it pulls), close the inlets, then the
        node."""
        self._stop_reading.set()
        if self._reader is not None:
            self._reader.join(timeout=5.0)
        self.acq.close()
        for line in self._files.close() if self._files is not None else ():
            self.get_logger().warning(line)
        if self.markers is not None:
            self.markers.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Run the node until Ctrl-C or ``duration``; exit 1 when the stream is not found or has the
    wrong layout, 2 on a bad parameter (one line each)."""
    return run_node(AcquisitionNode, args, errors=(EEGError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
