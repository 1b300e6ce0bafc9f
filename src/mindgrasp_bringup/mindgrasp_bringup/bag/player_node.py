"""Player node: publishes a bag's messages with their original timing (like ``ros2 bag play``).

Run: ``python -m mindgrasp_bringup.bag.player_node --ros-args -p bag:=runs/x/bag -p rate:=2.0
-p clock:=true``. Publishes the recorded CDR bytes unchanged (raw publishers) with the QoS the
recording offered; topics whose type the client layer cannot publish are skipped and named.
"""

from __future__ import annotations

import signal
import sys
import threading
from typing import Any

from mindgrasp_bringup.bag.errors import BagError
from mindgrasp_bringup.bag.paths import resolve_bag
from mindgrasp_bringup.bag.player import Player, PlayStats, parse_remaps, type_problem
from mindgrasp_bringup.bag.qos import adapted_qos
from mindgrasp_bringup.bag.reader import BagReader, TopicInfo
from mindgrasp_bringup.bag.ros_glue import message_class, qos_profile
from mindgrasp_bringup.bag.typestore import typestore
from mindgrasp_ros import rclpy

CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
TIME_TYPE = 'builtin_interfaces/msg/Time'


class PlayerNode(rclpy.node.Node):
    """Opens the bag, creates one raw publisher per playable topic, plays in a thread."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('bag_player', **kwargs)
        self.declare_parameters('', [
            ('bag', ''), ('rate', 1.0), ('loop', False), ('start_offset', 0.0),
            ('topics', ['']), ('regex', ''), ('exclude_regex', ''), ('remap', ['']),
            ('clock', False), ('clock_frequency', 40.0), ('delay', 0.0), ('priority', 0),
            ('progress', False)])
        v = {name: self.get_parameter(name).value for name in (
            'bag', 'rate', 'loop', 'start_offset', 'topics', 'regex', 'exclude_regex', 'remap',
            'clock', 'clock_frequency', 'delay', 'priority', 'progress')}
        if not v['bag']:
            msg = 'The parameter bag is empty; pass the bag directory with -p bag:=<path>.'
            raise BagError(msg)
        self.reader = BagReader(resolve_bag(v['bag'])).open()  # a run directory or its bag
        for note in self.reader.notes:
            self.get_logger().warning(note)
        topics = [t for t in (v['topics'] or []) if t] or None
        self.remap = parse_remaps([r for r in (v['remap'] or []) if r])
        self.publishers_: dict[str, Any] = {}
        self.player = Player(
            self.reader, rate=float(v['rate']), loop=bool(v['loop']),
            start_offset=float(v['start_offset']), topics=topics, regex=v['regex'],
            exclude_regex=v['exclude_regex'], remap=self.remap,
            can_publish=self._create_publisher)
        for line in self.player.skipped_report():
            self.get_logger().warning(line)
        self.clock_publisher = None
        self.clock_frequency = float(v['clock_frequency'])
        if v['clock']:
            clock_qos = rclpy.qos.QoSProfile(depth=1,
                                             reliability=rclpy.qos.ReliabilityPolicy.BEST_EFFORT)
            self.clock_publisher = self.create_publisher(
                message_class(CLOCK_TYPE), '/clock', clock_qos, raw=True)
        self.delay = float(v['delay'])
        self.priority = int(v['priority'])
        self.progress = bool(v['progress'])
        self.stats: PlayStats | None = None
        self.error: str | None = None
        self.stop_event = threading.Event()
        self.thread = threading.Thread(target=self._play, name='bag-player', daemon=True)

    def _create_publisher(self, info: TopicInfo) -> str | None:
        """Create the raw publisher of one bag topic; the reason when it cannot be played."""
        reason = type_problem(info)
        if reason:
            return reason
        try:
            msg_class = message_class(info.type)
        except (ImportError, AttributeError, ValueError):
            return f'its message type {info.type} is unknown to the client layer'
        qos = adapted_qos(info.offered_qos_profiles)
        out = self.remap.get(info.name, info.name)
        if out in self.publishers_:   # two bag topics remapped onto one: one publisher
            return None
        self.publishers_[out] = self.create_publisher(msg_class, out, qos_profile(rclpy, qos),
                                                      raw=True)
        return None

    def start(self) -> None:
        """Start playing (after ``delay`` s, so subscribers can match first)."""
        self.thread.start()

    def _play(self) -> None:
        if self.delay > 0 and self.stop_event.wait(self.delay):
            return
        store = typestore()
        clock_class, time_class = store.types[CLOCK_TYPE], store.types[TIME_TYPE]
        publishers = self.publishers_   # keyed by output topic, as the player reports them

        from tqdm import tqdm

        total = sum(info.message_count for info in self.reader.topics.values()
                    if self.remap.get(info.name, info.name) in publishers)
        bar = tqdm(total=None if self.player.loop else total, unit='msg', desc='bag play',
                   disable=not self.progress, file=sys.stderr)

        def publish(topic: str, data: bytes) -> None:
            publishers[topic].publish(data)
            bar.update(1)

        def publish_clock(ns: int) -> None:
            sec, nanosec = divmod(ns, 1_000_000_000)
            msg = clock_class(clock=time_class(sec=sec, nanosec=nanosec))
            self.clock_publisher.publish(  # type: ignore[union-attr]
                bytes(store.serialize_cdr(msg, CLOCK_TYPE)))

        # rosbags builds a type's serializer on its first use (several ms): not on the schedule
        store.serialize_cdr(clock_class(clock=time_class(sec=0, nanosec=0)), CLOCK_TYPE)
        try:
            self.stats = self.player.run(
                publish,
                publish_clock=publish_clock if self.clock_publisher is not None else None,
                clock_hz=self.clock_frequency, stop=self.stop_event, priority=self.priority)
            for note in self.stats.notes:
                self.get_logger().warning(note)
        except BagError as exc:
            self.error = str(exc)
            self.get_logger().error(self.error)
        finally:
            bar.close()


def main(args: list[str] | None = None) -> int:
    """Play the bag; 0 when played to the end (or stopped), 1 on a bag error."""
    # The playback thread shares the GIL with the executor thread; Python's default 5 ms switch
    # interval would delay publications by up to 5 ms. 0.5 ms keeps them on time.
    sys.setswitchinterval(0.0005)
    rclpy.init(args=args)
    try:
        node = PlayerNode()
    except BagError as exc:
        print(f'bag player: {exc}', file=sys.stderr)
        rclpy.shutdown()
        return 1
    signal.signal(signal.SIGTERM, lambda *_: node.stop_event.set())
    node.start()
    try:
        while rclpy.ok() and node.thread.is_alive():
            # Short non-blocking spins: a blocking spin keeps the GIL busy enough to delay the
            # playback thread by several ms; parameter services still answer within 50 ms.
            rclpy.spin_once(node, timeout_sec=0.0)
            node.thread.join(0.05)
    except KeyboardInterrupt:
        pass
    finally:
        node.stop_event.set()
        node.thread.join(5.0)
        stats, error = node.stats, node.error
        if stats is not None:
            total = sum(stats.published.values())
            node.get_logger().info(f'Published {total} message(s) on {len(stats.published)} '
                                   f'topic(s); worst lateness {stats.max_late_ms:.1f} ms.')
        node.reader.close()
        node.destroy_node()
        if rclpy.ok():
            rclpy.shutdown()
    return 1 if error else 0


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
