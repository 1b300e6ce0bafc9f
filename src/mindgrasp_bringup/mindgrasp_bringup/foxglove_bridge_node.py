"""Live view node: the graph's topics over the Foxglove WebSocket protocol, for the experimenter.

    ros2 run mindgrasp_bringup foxglove_bridge_node          # or: mindgrasp launch demo
    python -m mindgrasp_bringup.foxglove_bridge_node --ros-args -p port:=8766

Open Foxglove (desktop app, or app.foxglove.dev in a browser on this machine), "Open connection",
``ws://localhost:8765``; the layout ``foxglove/mindgrasp_live.json`` of mindgrasp_bringup
shows the camera with its overlay, the 3D scene (TF + URDF from /robot_description), the arm
joints, the EEG traces, the prediction certainty and the controller state. The layout follows the
robot (``robot:=``): in a launch the node writes that robot's layout into the run directory
(``<run>/foxglove/``, ``layout_dir:=`` elsewhere) and logs where (mindgrasp_bringup.live_layout).

Like foxglove_bridge (its parameter names ``port``, ``address``, ``topic_whitelist``): every topic
that has a publisher and matches a ``topic_whitelist`` regex is advertised with its ROS 2 schema;
the node subscribes to it (raw CDR, with the publishers' QoS: transient local for
/robot_description and /tf_static, best effort for the camera) only while a client watches it, so
an unwatched live view costs the graph nothing. The watched topics are read every
``poll_period`` (40 ms) and sent on in one burst, which costs a half to a third of the CPU of
waking for each message (benchmarks/live_view.py); with the real rclpy, or ``poll_period:=0``,
each message is sent on as it arrives. A slow client loses its oldest messages beyond
``message_backlog_size``, and the node warns about it; the graph never waits for it. Listens on
loopback only unless ``address`` says otherwise. A port in use ends the node with exit code 2 and
one line naming the port and the fix (``port:=``), as foxglove_bridge; with ``port_in_use:=skip``
(the launch profiles) the line is an error log and the node ends with 0, so the rest of a launch
runs on without its live view.
"""

from __future__ import annotations

import os
import re
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mindgrasp_bag.qos import adapted_qos, qos_to_dict, resubscribe_qos
from mindgrasp_bag.ros_glue import message_class, qos_profile
from mindgrasp_bringup.live_layout import write_layouts
from mindgrasp_bringup.live_view import DEFAULT_PORT, FoxgloveServer, LiveViewError
from mindgrasp_common.robot import DEFAULT_ROBOT
from mindgrasp_common.robot_description import RobotDescriptionError, load_robot
from mindgrasp_ros import rclpy, using_real_rclpy
from mindgrasp_ros.node_main import end_after, run_node
from mindgrasp_ros.params import ParameterError, declare_params, param
from mindgrasp_ros.typesupport import message_definition

#: ROS graph topics nobody needs in the view
_EXCLUDED = ('/rosout', '/parameter_events')


@dataclass
class BridgeParams:
    """Parameters of the live view node (names as foxglove_bridge's)."""

    port: int = param(DEFAULT_PORT, 'TCP port of the WebSocket server (0: any free port)',
                      min=0, max=65535)
    address: str = param('127.0.0.1', 'address to listen on (loopback: this machine only)')
    # the launch profiles say 'skip': a second demo on this machine must not stop for its view
    port_in_use: str = param('fail', "when the port is taken: 'fail' (exit 2, as "
                             "foxglove_bridge) or 'skip' (log the error and end with 0: the rest "
                             'of a launch runs on without the view)', choices=('fail', 'skip'))
    # param() returns a dataclasses.field with a default_factory for lists
    topic_whitelist: list[str] = param(['.*'], 'regexes of the topics to serve')
    message_backlog_size: int = param(
        1024, 'messages queued per client before its oldest are dropped', min=1)
    discovery_period: float = param(1.0, 'how often new topics are looked for', unit='s',
                                    min=0.05)
    duration: float = param(0.0, 'end after this long (0: run until stopped)', unit='s', min=0.0)
    poll_period: float = param(
        0.04, 'how often the watched topics are read and sent on, in one burst (0: each message '
        'as it arrives, at two to three times the CPU)', unit='s', min=0.0)

    robot: str = param(DEFAULT_ROBOT, 'the robot the layout follows (3D view root, joint plot '
                       'labels): a shipped robot or a robot description YAML path')
    layout_dir: str = param('', "where to write the robot's layout files ('': "
                            "$MINDGRASP_RUN_DIR/foxglove in a launch, none outside one)")

    def __post_init__(self) -> None:
        load_robot(self.robot)   # a bad description: one line before the server starts
        for pattern in self.topic_whitelist:
            try:
                re.compile(pattern)
            except re.error as exc:
                msg = (f"topic_whitelist entry {pattern!r} is not a regular expression ({exc}); "
                       f"fix it, e.g. topic_whitelist:=\"['/camera/.*', '/tf']\".")
                raise ParameterError(msg) from None


class FoxgloveBridgeNode(rclpy.node.Node):
    """Subscribes to the graph's topics as they appear and forwards them to Foxglove clients."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('foxglove_bridge', **kwargs)
        self.params = declare_params(self, BridgeParams)
        self.done = rclpy.task.Future()
        self.whitelist = [re.compile(p) for p in self.params.topic_whitelist]
        # the SDK's thread triggers it when a client (un)subscribes: no polling timer, so an
        # idle view wakes the node once per discovery period only
        client_events = self.create_guard_condition(self.clients_callback)
        server_options = {'message_backlog_size': self.params.message_backlog_size,
                          'on_subscription_change': client_events.trigger}
        try:
            self.server = FoxgloveServer(self.params.address, self.params.port, **server_options)
        except LiveViewError as exc:
            if self.params.port_in_use != 'skip' or 'in use' not in str(exc):
                raise
            # not a free port instead: a view on a port nobody asked for is one nobody finds
            self.server = None
            self.get_logger().error(f'{exc} The live view is off; the rest runs on.')
            self.done.set_result(0)
            return
        self._types: dict[str, str] = {}                   # advertised topic -> type
        self._subscriptions: dict[str, Any] = {}           # watched topic -> subscription
        self._requested: dict[str, dict[str, Any]] = {}    # watched topic -> QoS
        self.get_logger().info(f'Live view on {self.server.url}: open it in Foxglove '
                               '(Open connection > Foxglove WebSocket).')
        self._write_layout()
        self.create_timer(self.params.discovery_period, self.discover_callback)
        # polled subscriptions are this runtime's (rclpy has no take); the timer runs only while
        # a client watches something
        polling = self.params.poll_period > 0 and not using_real_rclpy()
        self._poll_timer = (self.create_timer(self.params.poll_period, self.poll_callback,
                                              autostart=False) if polling else None)
        end_after(self, self.params.duration)
        self.discover_callback()

    def _write_layout(self) -> None:
        """Write the layout of the robot into ``layout_dir`` (or the run directory's
        ``foxglove/``) and say where; a failed write is a warning: the view still serves."""
        run_dir = os.environ.get('MINDGRASP_RUN_DIR', '')
        folder = self.params.layout_dir or (str(Path(run_dir) / 'foxglove') if run_dir else '')
        if not folder:
            return
        try:
            path = write_layouts(Path(folder), self.params.robot)[0]
        except OSError as exc:
            self.get_logger().warning(f'Cannot write the layout into {folder} ({exc}); the live '
                                      'view runs on without it.')
            return
        self.get_logger().info(f"Layout for the robot {self.params.robot!r}: {path} (Layouts > "
                               'Import from file).')

    def _wanted(self, topic: str) -> bool:
        return topic not in _EXCLUDED and any(p.fullmatch(topic) for p in self.whitelist)

    def discover_callback(self) -> None:
        """Advertise every new wanted topic that has a publisher; re-match QoS of watched ones."""
        for topic, types in self.get_topic_names_and_types():
            if not self._wanted(topic) or topic in self._types:
                if self._subscriptions.get(topic) is not None:
                    offered = [qos_to_dict(i.qos_profile)
                               for i in self.get_publishers_info_by_topic(topic)]
                    again = resubscribe_qos(self._requested[topic], offered, default_depth=10)
                    if again is not None:
                        self._subscribe(topic, again)
                continue
            offered = [qos_to_dict(i.qos_profile)
                       for i in self.get_publishers_info_by_topic(topic)]
            if not offered:
                continue
            self._types[topic] = types[0]
            try:
                definition = message_definition(types[0])
            except Exception as exc:  # a type our typestore does not know: skip, say why
                self.get_logger().warning(f'Not serving {topic}: its type {types[0]} is unknown '
                                          f'here ({exc}).')
                continue
            qos = adapted_qos(offered, default_depth=10)
            latched = qos['durability'] == 'transient_local'
            self.server.add_channel(topic, types[0], definition,
                                    latched_depth=qos['depth'] if latched else 0)

    def clients_callback(self) -> None:
        """Subscribe to a topic when a client starts watching it, drop it when nobody does; say
        when a client is too slow for what it watches."""
        for event, topic in self.server.events():
            if event == 'dropping':
                self.get_logger().warning(
                    f'Live view client {topic} is too slow: its oldest messages were dropped '
                    f'(more than message_backlog_size={self.params.message_backlog_size} '
                    'queued); the graph does not wait for it. Watch fewer topics in it, or give '
                    'it a faster link.')
                continue
            if topic not in self.server.topics:
                continue
            if event == 'subscribe':
                if self._subscriptions.get(topic) is None:
                    offered = [qos_to_dict(i.qos_profile)
                               for i in self.get_publishers_info_by_topic(topic)]
                    self._subscribe(topic, adapted_qos(offered, default_depth=10))
                else:  # already watched: latched data goes to the new client too
                    self.server.resend_latched(topic)
            elif not self.server.wanted(topic) and self._subscriptions.get(topic) is not None:
                self.destroy_subscription(self._subscriptions.pop(topic))
                if self._poll_timer is not None and not self._subscriptions:
                    self._poll_timer.cancel()

    def _subscribe(self, topic: str, qos: dict[str, Any]) -> None:
        old = self._subscriptions.get(topic)
        if old is not None:
            self.destroy_subscription(old)
        self._requested[topic] = qos

        def forward(data: bytes, topic: str = topic) -> None:
            self.server.log(topic, data, time.time_ns())

        polled: dict[str, bool] = {}
        if self._poll_timer is not None:
            polled = {'polled': True}
            if qos['durability'] != 'transient_local':
                # a period's worth of a fast topic (a 500 Hz arm driver) fits the reader's history
                qos = {**qos, 'depth': max(int(qos['depth']), 64)}
            if self._poll_timer.is_canceled():
                self._poll_timer.reset()
        self._subscriptions[topic] = self.create_subscription(
            message_class(self._types[topic]), topic, forward, qos_profile(rclpy, qos), raw=True,
            **polled)

    def poll_callback(self) -> None:
        """Send on what arrived on each watched topic since the last period, logged at the time
        its publisher wrote it."""
        now = time.time_ns()
        for topic, subscription in self._subscriptions.items():
            for data, info in subscription.take():
                self.server.log(topic, data, info.get('source_timestamp') or now)

    def destroy_node(self) -> None:
        if self.server is None:     # never served (port_in_use:=skip)
            super().destroy_node()
            return
        sent = sum(t.messages for t in self.server.topics.values())
        slow = ', '.join(f'{client} ({n})' for client, n in self.server.drop_reports.items())
        self.get_logger().info(f'Live view served {len(self.server.topics)} topic(s), '
                               f'{sent} message(s) to clients'
                               + (f'; reports of dropped messages: {slow}.' if slow else '.'))
        self.server.stop()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    return run_node(FoxgloveBridgeNode, args, errors=(LiveViewError, RobotDescriptionError))


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
