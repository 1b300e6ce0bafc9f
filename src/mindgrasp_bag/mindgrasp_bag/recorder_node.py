"""Recorder node: records all topics (or a pattern list) to a rosbag2 MCAP bag.

Run: ``python -m mindgrasp_bag.recorder_node --ros-args -p output:=runs/x/bag
-p topics:="['/eeg/raw']" -p duration:=10.0`` (parameters: :class:`RecorderParams`). New topics
are discovered while it runs; the subscriptions take raw CDR bytes, and a
:class:`~mindgrasp_bag.recorder.Recorder` writes them from its own thread, so callbacks
never wait for the disk.

QoS as rosbag2 does it: a topic is subscribed once it has a publisher (a topic that only has
subscribers is not, as ``ros2 bag record`` without ``--include-unpublished-topics``), with the QoS
adapted to the publishers found (best effort when any publisher is best effort, transient local
when all are). When a publisher appears later that the subscription cannot match (a best-effort
camera after a reliable one, a volatile publisher on a transient-local topic), the topic is
subscribed again with the relaxed QoS. At the end, every wanted topic that was not recorded is
reported with the reason, in the log and in metadata.yaml ``custom_data``
(``not_recorded:/topic``).

The bag is closed in ``destroy_node()``, so Ctrl-C, SIGTERM and the end of ``duration`` all keep
everything recorded (a SIGKILL leaves an unfinished MCAP file that ``mindgrasp bag reindex``
recovers). Exit codes: 0 recorded, 1 recording failed (full disk; the node keeps running until
stopped, as the error is logged at once), 2 bad parameter.
"""

from __future__ import annotations

import re
import signal
import sys
import threading
import time
from dataclasses import dataclass
from typing import Any

from mindgrasp_bag.errors import BagError
from mindgrasp_bag.param_changes import PARAMETER_EVENTS, ParameterChangeLog
from mindgrasp_bag.param_watch import ParameterWatch
from mindgrasp_bag.qos import adapted_qos, qos_to_dict, resubscribe_qos
from mindgrasp_bag.recorder import Recorder
from mindgrasp_bag.ros_glue import message_class, qos_profile
from mindgrasp_bag.writer import BagWriter
from mindgrasp_ros import rclpy
from mindgrasp_ros.logs import log_at
from mindgrasp_ros.node_main import NodeFailure, end_after, run_node
from mindgrasp_ros.node_traits import NodeTraits
from mindgrasp_ros.params import ParameterError, declare_params, param

#: Topics of the ROS graph itself, left out with include_ros_topics:=false.
_ALWAYS_EXCLUDED = ('/rosout', PARAMETER_EVENTS)


@dataclass
class RecorderParams:
    """Parameters of the recorder node (names as ``ros2 bag record``'s options)."""

    output: str = param('', "bag directory to create ('': rosbag2_<date>-<time>)")
    topics: list[str] = param([], 'topics to record (empty: every topic, or those matching '
                              'regex)')
    regex: str = param('', "record the topics matching this regular expression ('': no filter)")
    exclude_regex: str = param('', 'do not record the topics matching this regular expression')
    max_bag_size: int = param(0, 'start a new .mcap file at this size (0: never)', unit='B',
                              min=0)
    max_bag_duration: float = param(0.0, 'start a new .mcap file after this long (0: never)',
                                    unit='s', min=0.0)
    compression: str = param('none', 'MCAP chunk compression', choices=('none', 'zstd', 'lz4'))
    chunk_size: int = param(1 << 20, 'MCAP chunk size', unit='B', min=1)
    flush_interval: float = param(1.0, 'longest time before written messages reach the file '
                                  '(bounds the loss if the recorder is killed)', unit='s',
                                  min=0.001)
    max_queue_mb: int = param(512, 'memory for messages waiting for the disk', unit='MiB', min=1)
    discovery_period: float = param(0.5, 'how often new topics are looked for', unit='s',
                                    min=0.01)
    duration: float = param(0.0, 'end after this long (0: run until stopped)', unit='s', min=0.0)
    include_ros_topics: bool = param(True, 'record /rosout and /parameter_events too (as '
                                     "'ros2 bag record -a' does)")
    parameter_changes: str = param('', 'append every live parameter change to this JSONL file '
                                   "(time, node, name, old and new value; '': none)")
    # as ros2 bag record --custom-data: what the run was (the launch's robot:=) travels with the
    # bag, for a reader that has the bag folder only
    custom_data: list[str] = param([], 'KEY=VALUE pairs stored in metadata.yaml custom_data')

    def __post_init__(self) -> None:
        for item in self.custom_data:
            if not item.partition('=')[0].strip() or '=' not in item:
                msg = (f'custom_data entry {item!r} is not KEY=VALUE; write each as '
                       "key=value, e.g. custom_data:=\"['robot=xarm6']\".")
                raise ParameterError(msg)
        for name in ('regex', 'exclude_regex'):
            try:
                re.compile(getattr(self, name))
            except re.error as exc:
                msg = (f'The topic regular expression is not valid ({exc}); fix the {name} '
                       'parameter.')
                raise ParameterError(msg) from None


class RecorderNode(rclpy.node.Node):
    """Subscribes to matching topics as they appear and feeds a :class:`Recorder`."""

    # In lock-step /rosout and /parameter_events are left out: they name paths of the run, and
    # an experiment's bag is the same bit for bit when run again (nothing changes parameters
    # live in lock-step). The runner's own /clock is left out too, and the bag is the run's.
    node_traits = NodeTraits(lockstep_parameters={'include_ros_topics': False,
                                                  'parameter_changes': ''},
                             lockstep_exclude_parameter='exclude_regex',
                             lockstep_output_parameter='output')

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('recorder', **kwargs)
        self.params = p = declare_params(self, RecorderParams)
        self.done = rclpy.task.Future()
        self.topics = [t for t in p.topics if t]
        self.include = re.compile(p.regex) if p.regex else None
        self.exclude = re.compile(p.exclude_regex) if p.exclude_regex else None
        writer = BagWriter(p.output or time.strftime('rosbag2_%Y_%m_%d-%H_%M_%S'),
                           chunk_size=p.chunk_size, compression=p.compression,
                           flush_interval=p.flush_interval, max_bag_size=p.max_bag_size,
                           max_bag_duration=p.max_bag_duration,
                           custom_data=dict(item.split('=', 1) for item in p.custom_data))
        self.recorder = Recorder(writer, max_queue_bytes=p.max_queue_mb << 20,
                                 on_error=self._on_error)
        self.recorder.start()
        try:
            self._topic_subscriptions: dict[str, Any] = {}
            self._requested: dict[str, dict[str, Any]] = {}     # topic -> QoS subscribed with
            self._matched: set[str] = set()                     # topics that matched a publisher
            self._unpublished: set[str] = set()                 # seen with subscribers only
            self._refused: set[str] = set()
            self._types: dict[str, str] = {}
            self.param_watch = (ParameterWatch(self, ParameterChangeLog(p.parameter_changes))
                                if p.parameter_changes else None)
            self.get_logger().info(f'Recording to {writer.path} (MCAP, compression '
                                   f'{writer.compression}).')
            self.create_timer(p.discovery_period, self.discover_callback)
            self.create_timer(1.0, self.report_callback)
            end_after(self, p.duration)
            self.discover_callback()
        except BaseException:
            # cut short (a Ctrl-C while a lock-step graph starts): the bag is closed all the same
            self.recorder.stop()
            raise

    def _wanted(self, topic: str) -> bool:
        if topic in self.topics or (topic == PARAMETER_EVENTS and self.param_watch):
            return True
        if not self.params.include_ros_topics and topic in _ALWAYS_EXCLUDED:
            return False
        if self.exclude is not None and self.exclude.search(topic):
            return False
        if self.include is not None:
            return bool(self.include.search(topic))
        return not self.topics  # no list and no regex: everything

    def discover_callback(self) -> None:
        """Subscribe to every new matching topic that has a publisher; re-match changed ones."""
        if self.recorder.error is not None:
            return
        if self.param_watch is not None:
            self.param_watch.poll()
        for topic, types in self.get_topic_names_and_types():
            if topic in self._refused or not self._wanted(topic):
                continue
            offered = [qos_to_dict(i.qos_profile)
                       for i in self.get_publishers_info_by_topic(topic)]
            sub = self._topic_subscriptions.get(topic)
            if sub is not None:
                if sub.get_publisher_count() > 0:
                    self._matched.add(topic)
                new_qos = resubscribe_qos(self._requested[topic], offered, default_depth=100)
                if new_qos is not None:
                    self._subscribe(topic, self._types[topic], offered, new_qos, again=True)
                continue
            if not offered:  # subscribers only: nothing to record yet
                if topic not in self._unpublished:
                    self._unpublished.add(topic)
                    self.get_logger().info(f'Waiting for a publisher on {topic} (it has '
                                           'subscribers only).')
                continue
            msgtype = types[0]
            if len(types) > 1:
                self.get_logger().warning(f'{topic} is published with several types {types}; '
                                          f'recording {msgtype} only.')
            self._subscribe(topic, msgtype, offered, adapted_qos(offered, default_depth=100))

    def _subscribe(self, topic: str, msgtype: str, offered: list[dict[str, Any]],
                   qos: dict[str, Any], *, again: bool = False) -> None:
        try:
            msg_class = message_class(msgtype)
        except (ImportError, AttributeError, ValueError):
            self._refused.add(topic)
            self.get_logger().warning(f'Not recording {topic}: its type {msgtype} is unknown '
                                      'to the client layer (add its .msg to the type store).')
            return
        self._types[topic] = msgtype
        if not again:
            # The offered QoS stays that of the first publishers, as in rosbag2: the MCAP channel
            # holds it, and readers (rosbags) pair channels with metadata.yaml by it.
            self.recorder.add_topic(topic, msgtype, offered)
        old = self._topic_subscriptions.pop(topic, None)
        if old is not None:
            # Destroyed first: the middleware keeps one reader QoS per topic and process.
            self.destroy_subscription(old)
        self._requested[topic] = qos
        self._topic_subscriptions[topic] = self.create_subscription(
            msg_class, topic, self._make_callback(topic), qos_profile(rclpy, qos), raw=True)
        if again:
            self.get_logger().info(
                f'Subscribed again to {topic} with {qos["reliability"]}, {qos["durability"]}: '
                'a publisher appeared that the previous QoS could not match.')
        else:
            self.get_logger().info(f'Subscribed to {topic} ({msgtype}, {qos["reliability"]}, '
                                   f'{qos["durability"]}).')

    def not_recorded(self) -> dict[str, str]:
        """Wanted topics without any recorded message: topic -> why (a sentence)."""
        out: dict[str, str] = {}
        counters = self.recorder.counters
        for topic in sorted(set(self.topics) | self._unpublished | set(self._requested)):
            if counters.get(topic) is not None and counters[topic].received:
                continue
            if topic in self._requested:
                qos = self._requested[topic]
                if topic in self._matched:
                    out[topic] = 'its publishers sent nothing while recording.'
                else:
                    out[topic] = (f'the subscription ({qos["reliability"]}, '
                                  f'{qos["durability"]}) never matched a publisher (incompatible '
                                  'QoS, or the publisher left before matching).')
            elif topic in self._refused:
                out[topic] = 'its message type is unknown to the client layer.'
            elif topic in self._unpublished:
                out[topic] = ('it had subscribers but no publisher appeared while recording, so '
                              'it was never subscribed.')
            else:
                out[topic] = ('no node published or subscribed to it while recording (check the '
                              'topic name).')
        return out

    def _idle(self, topic: str) -> bool:
        """A topic nobody named that carried nothing in this run: its publishers had nothing to
        say, or it only had subscribers (``/trainer/prompt`` in a demo without a trainer). Not a
        fault, so its "not recorded" line is info (still in metadata.yaml); a topic named in
        ``topics``, a QoS that never matched and an unknown type stay warnings."""
        if topic in self.topics:
            return False
        matched_but_silent = topic in self._requested and topic in self._matched
        listened_only = topic in self._unpublished and topic not in self._requested
        return matched_but_silent or listened_only

    def _make_callback(self, topic: str) -> Any:
        push = self.recorder.push
        clock = self.get_clock()
        watch = self.param_watch if topic == PARAMETER_EVENTS else None

        def callback(data: bytes, info: Any) -> None:
            # Two arguments: rclpy passes MessageInfo with the DDS source timestamp (ns).
            sent = info.get('source_timestamp') if isinstance(info, dict) else None
            now = clock.now().nanoseconds
            push(topic, data, now, sent or None)
            if watch is not None:   # the change log's time is the event's log time in the bag
                watch.event(bytes(data), now)
        return callback

    def report_callback(self) -> None:
        """Log drops and EEG gaps found since the last report."""
        for line in self.recorder.reports():
            self.get_logger().warning(line)

    def _on_error(self, message: str) -> None:
        # Called from the writer thread: log only; the node keeps running, subscriptions idle,
        # and ends with exit code 1 when stopped (destroy_node).
        self.get_logger().error(message)

    def destroy_node(self) -> None:
        """Close the bag (:meth:`stop`); a recording error ends the node with exit code 1."""
        previous = None
        if threading.current_thread() is threading.main_thread():
            # the launcher follows SIGINT with SIGTERM: that must not cut the bag's closing short
            previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)
        try:
            error = self.stop()
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
        if error is not None and not self.done.done():
            # logged already, when it happened: run_node prints it once more as the last line
            self.done.set_exception(NodeFailure(error))
        super().destroy_node()

    def stop(self) -> str | None:
        """Write what is queued and close the bag; log the counters and the topics not
        recorded (with the reason, also stored in metadata.yaml ``custom_data``). Returns the
        recording error (a sentence), None when everything was written."""
        for sub in self._topic_subscriptions.values():
            if sub.get_publisher_count() > 0:
                self._matched.add(sub.topic_name)
        missing = self.not_recorded()
        for topic, why in missing.items():
            self.recorder.writer.custom_data[f'not_recorded:{topic}'] = why
        if self.param_watch is not None:
            self.param_watch.log.close()
        try:
            counters = self.recorder.stop()
        except BagError as exc:
            self.get_logger().error(str(exc))
            return str(exc)
        for line in self.recorder.reports():
            self.get_logger().warning(line)
        total = sum(c.written for c in counters.values())
        dropped = sum(c.dropped_queue_full for c in counters.values())
        lost = sum(c.lost_disk_fault for c in counters.values())
        recorded = sum(1 for c in counters.values() if c.written)
        fault = f', {lost} lost to the write error' if self.recorder.error is not None else ''
        self.get_logger().info(f'Recorded {total} message(s) on {recorded} topic(s) to '
                               f'{self.recorder.writer.path}; {dropped} dropped{fault}; '
                               f'{len(missing)} topic(s) not recorded.')
        for topic, why in missing.items():
            log_at(self.get_logger(), 'info' if self._idle(topic) else 'warning',
                   f'Not recorded: {topic}: {why}')
        return self.recorder.error


def main(args: list[str] | None = None) -> int:
    """Record until Ctrl-C, SIGTERM or ``duration``; 1 if recording failed, 2 on a bad
    parameter."""
    # The writer thread shares the GIL with the callbacks; a 1 ms switch interval (default 5 ms)
    # keeps receive timestamps, and so playback timing, within ~1 ms of the arrival.
    sys.setswitchinterval(0.001)
    return run_node(RecorderNode, args, errors=(BagError,))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
