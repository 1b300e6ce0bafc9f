"""EEG acquisition node: one LSL EEG stream -> mindgrasp_msgs/EEGChunk on /eeg/raw.

    python -m mindgrasp_eeg.acquisition_node --ros-args -p stream_name:=MyAmp
    python -m mindgrasp_eeg.acquisition_node --ros-args \
        --params-file config/param/eeg.yaml

Publishes ``/eeg/raw`` (sensor-data QoS, depth 100) every ``chunk_period`` seconds with the
samples that arrived, in volts, stamped with the ROS time of the first sample (see
:mod:`mindgrasp_eeg.acquisition` for the LSL-to-ROS time mapping), and ``/eeg/status``
(diagnostic_msgs/DiagnosticArray, reliable) every ``status_period`` seconds and on every change
of level. All the work is done by :class:`~mindgrasp_eeg.acquisition.EEGAcquisition`.

The stream is looked for in a background thread (up to ``resolve_timeout`` s): meanwhile the node
answers signals at once and says "Searching for the LSL stream ..." on /eeg/status (WARN). Not
found in time, or a layout that does not match: exit 1 with the reason.

Markers: with ``marker_stream:=auto`` (``<stream_name>-markers``, as ``mindgrasp eeg play`` names
it) or ``marker_stream:=NAME`` the node also relays an LSL marker stream (type ``Markers``: an
amplifier's triggers, a stimulus PC) to ``/eeg/markers`` (mindgrasp_msgs/EEGMarker), each stamped
on the same LSL-to-ROS mapping as the EEG samples, so the recorder keeps them and the exports read
them as events (:mod:`mindgrasp_eeg.marker_inlet`). Off by default; a marker stream not found or
lost is one log line, never an exit.

Which sender is trusted: by default any stream with the right name (a warning says so). Pin the
amplifier with ``source_id`` and ``hostname`` (``hostname:=local`` means this host), so no other
sender on the network can stand in for it.
"""

from __future__ import annotations

import socket

import numpy as np
from mindgrasp_ros.interfaces.diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import EEGChunk, EEGMarker

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.acquisition import ERROR, OK, WARN, EEGAcquisition, read_clocks, ros_stamp_ns
from mindgrasp_eeg.marker_inlet import MarkerInlet, marker_stream_name
from mindgrasp_eeg.params import AcquisitionParams
from mindgrasp_eeg.ros_conversions import ns_to_time_fields
from mindgrasp_ros import rclpy
from mindgrasp_ros.logs import log_at
from mindgrasp_ros.node_main import end_after, fail, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import declare_params
from mindgrasp_ros.topics import EEG_MARKERS, EEG_RAW, EEG_STATUS

_LEVELS = {OK: DiagnosticStatus.OK, WARN: DiagnosticStatus.WARN, ERROR: DiagnosticStatus.ERROR}


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
        if not self.acq.pinned:
            self.get_logger().warning(
                'The EEG stream is not pinned: any LSL sender with this name is accepted. Set '
                'source_id and hostname (hostname:=local for this host) to accept only your '
                'amplifier.')
        self.get_logger().info(f'Searching for the LSL stream ({self._wanted}) for up to '
                               f'{p.resolve_timeout:g} s.')
        self.acq.start_search()
        self._n_warnings = 0
        self._last_level = -1
        self._last_stamp_ns = -1
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
                               f'(x{self.acq.scale:g} to volts); publishing /eeg/raw every '
                               f'{self.params.chunk_period * 1e3:.1f} ms.')
        self.status_callback()
        return True

    def poll_callback(self) -> None:
        """Pull what LSL has and publish it (once the stream is found); a stream not found or
        of the wrong layout ends the node with exit code 1 and the reason."""
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
        chunks = self.acq.poll()
        if chunks:
            lsl_now, ros_now = read_clocks(lambda: self.get_clock().now().nanoseconds)
            desc = self.acq.desc
            for chunk in chunks:
                stamp = ros_stamp_ns(float(chunk.timestamps[0]), lsl_now, ros_now)
                stamp = max(stamp, self._last_stamp_ns + 1)   # never backwards
                self._last_stamp_ns = stamp
                msg = EEGChunk(sample_rate=desc.sample_rate, channel_names=list(desc.channel_names),
                               n_samples=len(chunk.data), first_sample_index=chunk.first_index,
                               unit='V', data=np.ascontiguousarray(chunk.data).ravel())
                msg.header.stamp.sec, msg.header.stamp.nanosec = ns_to_time_fields(stamp)
                msg.header.frame_id = self.params.frame_id
                self.pub_raw.publish(msg)
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
        """Close the inlets, then the node."""
        self.acq.close()
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
