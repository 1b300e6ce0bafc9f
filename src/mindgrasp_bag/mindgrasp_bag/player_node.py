"""Player node: publishes a bag's messages with their original timing (like ``ros2 bag play``).

Run: ``python -m mindgrasp_bag.player_node --ros-args -p bag:=runs/x/bag -p rate:=2.0
-p clock:=true`` (parameters: :class:`PlayerParams`). Publishes the recorded CDR bytes unchanged
(raw publishers) with the QoS the recording offered; topics whose type the client layer cannot
publish are skipped and named.

The playback runs in its own thread on the bag's schedule; the node ends when it has played the
bag (exit 0), on Ctrl-C/SIGTERM (0, within the current wait), on a bag error while playing (1),
or refuses to start on a bad parameter or an unreadable bag (2). A damaged bag (see
:mod:`.damage`) is played as far as it is readable, what was lost is logged before the first
message, and the node ends with exit code 1 unless ``allow_damaged`` is true.
"""

from __future__ import annotations

import sys
import threading
import traceback
from dataclasses import dataclass
from typing import Any

from mindgrasp_bag.damage import assess_bag
from mindgrasp_bag.errors import BagError
from mindgrasp_bag.paths import resolve_bag
from mindgrasp_bag.player import Player, PlayStats, parse_remaps, type_problem
from mindgrasp_bag.qos import adapted_qos
from mindgrasp_bag.reader import BagReader, TopicInfo
from mindgrasp_bag.ros_glue import message_class, qos_profile
from mindgrasp_bag.typestore import typestore
from mindgrasp_ros import rclpy
from mindgrasp_ros.node_main import fail, run_node
from mindgrasp_ros.params import ParameterError, declare_params, param
from mindgrasp_ros.topics import CLOCK

CLOCK_TYPE = 'rosgraph_msgs/msg/Clock'
TIME_TYPE = 'builtin_interfaces/msg/Time'


@dataclass
class PlayerParams:
    """Parameters of the player node (names as ``ros2 bag play``'s options)."""

    bag: str = param('', 'run directory (runs/<run>), bag directory or .mcap/.db3 file')
    rate: float = param(1.0, 'playback speed factor (1.0: real time; > 0)', min=0.0)
    loop: bool = param(False, 'play again from the start when the bag ends')
    start_offset: float = param(0.0, 'skip this long of the bag beginning', unit='s', min=0.0)
    topics: list[str] = param([], 'play only these topics (empty: every topic)')
    regex: str = param('', "play only the topics matching this regular expression ('': all)")
    exclude_regex: str = param('', 'do not play the topics matching this regular expression')
    remap: list[str] = param([], 'publish a topic under another name: /from:=/to entries')
    clock: bool = param(False, 'publish /clock with the bag time')
    clock_frequency: float = param(40.0, 'rate of /clock', unit='Hz', min=0.001)
    delay: float = param(0.0, 'wait this long after creating the publishers, so subscribers '
                         'match before the first message', unit='s', min=0.0)
    priority: int = param(0, 'real-time (SCHED_FIFO) priority of the playback thread (0: '
                          'normal; needs root or CAP_SYS_NICE)', min=0, max=99)
    progress: bool = param(False, 'show a progress bar on stderr')
    allow_damaged: bool = param(False, 'end with exit code 0 after playing the readable part '
                                'of a damaged bag (default: 1, after playing it)')

    def __post_init__(self) -> None:
        if not self.rate > 0:
            msg = f"The parameter 'rate' must be > 0 (1.0 = real time); {self.rate} is invalid."
            raise ParameterError(msg)


class PlayerNode(rclpy.node.Node):
    """Opens the bag, creates one raw publisher per playable topic, plays in a thread."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('bag_player', **kwargs)
        self.params = p = declare_params(self, PlayerParams)
        self.done = rclpy.task.Future()
        if not p.bag:
            msg = 'The parameter bag is empty; pass the bag directory with -p bag:=<path>.'
            raise ParameterError(msg)
        self.reader = BagReader(resolve_bag(p.bag)).open()  # a run directory or its bag
        for note in self.reader.notes:
            self.get_logger().warning(note)
        self.damage = assess_bag(self.reader.path)   # said before anything is published
        for line in self.damage.lines():
            self.get_logger().warning(f'Damaged bag: {line}')
        self.remap = parse_remaps([r for r in p.remap if r])
        self.publishers_: dict[str, Any] = {}
        self.player = Player(
            self.reader, rate=p.rate, loop=p.loop, start_offset=p.start_offset,
            topics=[t for t in p.topics if t] or None, regex=p.regex,
            exclude_regex=p.exclude_regex, remap=self.remap, can_publish=self._create_publisher)
        for line in self.player.skipped_report():
            self.get_logger().warning(line)
        self.clock_publisher = None
        if p.clock:
            self.clock_publisher = self.create_publisher(
                message_class(CLOCK_TYPE), CLOCK.name, CLOCK.qos, raw=True)
        self.stats: PlayStats | None = None
        self._prepare_publishing()
        self.get_logger().info(f'Playing {self.reader.path} ({len(self.publishers_)} topic(s), '
                               f'rate {p.rate:g}).')
        self.stop_event = threading.Event()
        self.thread = threading.Thread(target=self._play, name='bag-player', daemon=True)
        self.thread.start()   # after ``delay`` s, so subscribers can match first

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

    def _play(self) -> None:
        try:
            if not (self.params.delay > 0 and self.stop_event.wait(self.params.delay)):
                self._play_bag()
            if self.damage.damaged and not self.params.allow_damaged and not self.done.done():
                fail(self, f'The bag is damaged; its readable part was played. '
                           f'{self.damage.count_line()} Pass --allow-damaged (-p '
                           'allow_damaged:=true) to accept it, or repair it with `mindgrasp '
                           'bag reindex`.')
        finally:
            if not self.done.done():
                self.done.set_result(0)

    def _prepare_publishing(self) -> None:
        """Everything the playback thread needs before its first wait (the type store, the
        progress bar, a first serialisation), done before the node says it plays: a thread busy
        with it would answer a stop only after it (seconds on a loaded machine)."""
        from tqdm import tqdm

        store = typestore()
        clock_class, time_class = store.types[CLOCK_TYPE], store.types[TIME_TYPE]
        publishers = self.publishers_   # keyed by output topic, as the player reports them
        total = sum(info.message_count for info in self.reader.topics.values()
                    if self.remap.get(info.name, info.name) in publishers)
        bar = tqdm(total=None if self.player.loop else total, unit='msg', desc='bag play',
                   disable=not self.params.progress, file=sys.stderr)

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
        self._bar, self._publish = bar, publish
        self._publish_clock = publish_clock if self.clock_publisher is not None else None

    def _play_bag(self) -> None:
        try:
            self.stats = self.player.run(
                self._publish, publish_clock=self._publish_clock,
                clock_hz=self.params.clock_frequency, stop=self.stop_event,
                priority=self.params.priority)
            for note in self.stats.notes:
                self.get_logger().warning(note)
        except BagError as exc:
            fail(self, str(exc))
        finally:
            self._bar.close()

    def destroy_node(self) -> None:
        """Stop the playback (Ctrl-C, SIGTERM), log what was published, close the bag."""
        self.stop_event.set()
        self.thread.join(5.0)
        if self.thread.is_alive():    # say where it hangs: a stop must take one wait (50 ms)
            frame = sys._current_frames().get(self.thread.ident)
            where = ''.join(traceback.format_stack(frame)[-4:]) if frame else '?'
            self.get_logger().error(f'The playback thread did not stop within 5 s; it is at:\n'
                                    f'{where}')
        if self.stats is not None:
            total = sum(self.stats.published.values())
            self.get_logger().info(f'Published {total} message(s) on {len(self.stats.published)} '
                                   f'topic(s); worst lateness {self.stats.max_late_ms:.1f} ms.')
        self.reader.close()
        super().destroy_node()


def main(args: list[str] | None = None) -> int:
    """Play the bag; 0 when played to the end (or stopped), 1 on a bag error while playing, 2 on
    a bad parameter or bag."""
    # The playback thread shares the GIL with the executor thread; Python's default 5 ms switch
    # interval would delay publications by up to 5 ms. 0.5 ms keeps them on time.
    sys.setswitchinterval(0.0005)
    # poll_sec: a main thread waiting in the middleware was found to delay the playback thread by
    # several ms; polling every 50 ms still answers parameter services (benchmarks/player.py
    # compares both: at load 9 on 2 cores the two were within noise of each other).
    return run_node(PlayerNode, args, errors=(BagError,), poll_sec=0.05)


if __name__ == '__main__':
    from mindgrasp_ros.process import run_program

    run_program(main)   # ends right after the node's cleanup: no slow interpreter teardown
