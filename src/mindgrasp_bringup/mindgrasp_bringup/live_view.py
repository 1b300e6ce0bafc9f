"""The Foxglove live view: ROS 2 topics served over the Foxglove WebSocket protocol (ROS-free).

:class:`FoxgloveServer` wraps the ``foxglove-sdk`` WebSocket server. Each ROS topic becomes one
channel with its ROS 2 schema (``ros2msg`` encoding: the full message definition with its
dependencies, as rosbag2 stores it in MCAP) and CDR messages, so the Foxglove app decodes them as
it decodes a ROS 2 bag or ``foxglove_bridge``::

    server = FoxgloveServer(host='127.0.0.1', port=8765)     # LiveViewError: port in use
    server.add_channel('/fsm/state', 'mindgrasp_msgs/msg/FsmState', definition_text)
    server.log('/fsm/state', cdr_bytes, time_ns)              # never blocks
    server.stop()

A slow client never slows the caller: :meth:`log` hands the message to the SDK, which queues at most
``message_backlog_size`` messages per client and drops that client's oldest ones beyond it.
:meth:`events` tells which channels clients (un)subscribed, so the caller subscribes to a ROS
topic only while someone watches it (as foxglove_bridge does), and which clients lose messages.

The SDK counts no dropped messages: it logs "outbox for client <address> full" (through Python's
``logging``, at most once per 30 s per process). :attr:`FoxgloveServer.drop_reports` counts those
reports per client address; the number of messages behind a report is not known.
"""

from __future__ import annotations

import collections
import ipaddress
import logging
import queue
import re
import weakref
from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = ['DEFAULT_PORT', 'FoxgloveServer', 'LiveViewError']

#: the Foxglove app's default WebSocket address is ws://localhost:8765
DEFAULT_PORT = 8765


class LiveViewError(Exception):
    """The live view cannot start (port in use, bad address); the message says the fix."""


@dataclass
class _Topic:
    channel: object
    type_name: str
    messages: int = 0        #: messages handed to the server
    skipped: int = 0         #: messages not serialised for anyone (no client subscribed)
    #: latched topics (transient local): the last messages, sent again to a new subscriber
    latched: collections.deque = field(default_factory=lambda: collections.deque(maxlen=0))


class _Listener:
    """foxglove ServerListener: queues client (un)subscriptions (and drop reports) for the
    caller's thread and calls ``notify`` (from the SDK's thread) after each."""

    def __init__(self, notify: Callable[[], None] | None = None) -> None:
        self.events: queue.SimpleQueue[tuple[str, str]] = queue.SimpleQueue()
        self.notify = notify

    def put(self, event: str, name: str) -> None:
        self.events.put((event, name))
        if self.notify is not None:
            self.notify()

    def on_subscribe(self, client: object, channel: object) -> None:
        self.put('subscribe', channel.topic)  # type: ignore[attr-defined]

    def on_unsubscribe(self, client: object, channel: object) -> None:
        self.put('unsubscribe', channel.topic)  # type: ignore[attr-defined]


#: what the SDK logs (foxglove.websocket.connected_client.send_lossy) when a client's queue is full
_DROP_REPORT = re.compile(r'outbox for client (\S+) full')


class _SdkDropReports(logging.Handler):
    """Reads the SDK's log records (Rust ``log`` to Python ``logging`` via pyo3-log) and passes
    each "outbox for client <address> full" to the servers of this process."""

    def __init__(self) -> None:
        super().__init__(logging.INFO)
        self.servers: weakref.WeakSet[FoxgloveServer] = weakref.WeakSet()

    def emit(self, record: logging.LogRecord) -> None:
        match = _DROP_REPORT.search(record.getMessage())
        if match is not None:
            for server in list(self.servers):
                server._drop_reported(match.group(1))


_DROP_REPORTS = _SdkDropReports()


def _watch_drop_reports(server: FoxgloveServer) -> None:
    # before the server starts: pyo3-log caches each logger's level when it first logs
    logger = logging.getLogger('foxglove.websocket')
    if _DROP_REPORTS not in logger.handlers:
        logger.addHandler(_DROP_REPORTS)
    if logger.getEffectiveLevel() > logging.INFO:
        logger.setLevel(logging.INFO)
    _DROP_REPORTS.servers.add(server)


class FoxgloveServer:
    """A Foxglove WebSocket server with one channel per ROS topic.

    Parameters
    ----------
    host : str
        Address to listen on; loopback (``127.0.0.1``) by default so only this machine sees the
        data. Another address exposes the EEG and camera to the network.
    port : int
        TCP port (0: any free port, see :attr:`port`).
    message_backlog_size : int
        Messages queued per client before its oldest are dropped (a slow client loses frames,
        the graph does not wait).
    on_subscription_change : callable | None
        Called with no argument, from the SDK's thread, when a client (un)subscribes or loses
        messages: e.g. a ROS guard condition's ``trigger``, so the caller reads :meth:`events`
        when there are some instead of polling.
    """

    def __init__(self, host: str = '127.0.0.1', port: int = DEFAULT_PORT, *,
                 message_backlog_size: int = 1024, name: str = 'MIndGrasp-ROS',
                 on_subscription_change: Callable[[], None] | None = None) -> None:
        import foxglove

        try:
            ipaddress.ip_address(host)
        except ValueError:
            msg = (f"The live view address {host!r} is not an IP address; use 127.0.0.1 "
                   f"(this machine only) or 0.0.0.0 (every interface).")
            raise LiveViewError(msg) from None
        if not 0 <= int(port) <= 65535:
            msg = f'The live view port {port} is not a TCP port; give 1-65535 (0: any free one).'
            raise LiveViewError(msg)
        self._foxglove = foxglove
        self._context = foxglove.Context()  # our own: channels of other code stay out
        self._listener = _Listener(on_subscription_change)
        #: client address -> "outbox full" reports of the SDK (it dropped that client's oldest
        #: messages; at most one report per 30 s per process)
        self.drop_reports: collections.Counter[str] = collections.Counter()
        _watch_drop_reports(self)
        try:
            self._server = foxglove.start_server(
                name=name, host=host, port=int(port), context=self._context,
                message_backlog_size=int(message_backlog_size),
                supported_encodings=['cdr'], server_listener=self._listener)
        except RuntimeError as exc:
            if 'in use' in str(exc).lower():
                msg = (f'The live view port {port} on {host} is in use (another live view or '
                       f'foxglove_bridge?): stop it, or pick another port with '
                       f'live_view_port:=<port> (node parameter port:=<port>).')
            else:
                msg = f'The live view cannot listen on {host}:{port}: {exc}.'
            raise LiveViewError(msg) from None
        self.host = host
        self.topics: dict[str, _Topic] = {}

    @property
    def port(self) -> int:
        """The TCP port the server listens on."""
        return int(self._server.port)

    @property
    def url(self) -> str:
        """``ws://<host>:<port>``, what to open in Foxglove."""
        host = 'localhost' if self.host in ('127.0.0.1', '0.0.0.0') else self.host
        return f'ws://{host}:{self.port}'

    def add_channel(self, topic: str, type_name: str, definition: str, *,
                    latched_depth: int = 0) -> None:
        """Advertise ``topic`` with its type (``pkg/msg/Type``) and ros2msg definition text.

        ``latched_depth`` > 0 (a transient-local topic such as /robot_description): its last
        messages are kept and sent again when a client subscribes (see :meth:`resend_latched`).
        """
        if topic in self.topics:
            return
        schema = self._foxglove.Schema(name=type_name, encoding='ros2msg',
                                       data=definition.encode('utf-8'))
        channel = self._foxglove.Channel(topic, schema=schema, message_encoding='cdr',
                                         context=self._context)
        self.topics[topic] = _Topic(channel, type_name,
                                    latched=collections.deque(maxlen=max(0, latched_depth)))

    def wanted(self, topic: str) -> bool:
        """Whether a client is subscribed to ``topic`` (else logging it is wasted work)."""
        entry = self.topics.get(topic)
        return entry is not None and bool(entry.channel.has_sinks())

    def log(self, topic: str, cdr: bytes, time_ns: int) -> None:
        """Send one CDR message (with its 4-byte encapsulation header) to the subscribed
        clients; ``time_ns``: receive time (ns since the epoch). Never blocks."""
        entry = self.topics[topic]
        if entry.latched.maxlen:
            entry.latched.append((bytes(cdr), int(time_ns)))
        if not entry.channel.has_sinks():
            entry.skipped += 1
            return
        entry.channel.log(bytes(cdr), log_time=int(time_ns))
        entry.messages += 1

    def _drop_reported(self, client: str) -> None:
        self.drop_reports[client] += 1
        self._listener.put('dropping', client)

    def events(self) -> list[tuple[str, str]]:
        """What happened since the last call: ``('subscribe' | 'unsubscribe', topic)`` and
        ``('dropping', client address)`` (the SDK dropped that client's oldest messages). The
        SDK reports them from its own threads; call this from the thread that calls :meth:`log`."""
        out = []
        while True:
            try:
                out.append(self._listener.events.get_nowait())
            except queue.Empty:
                return out

    def resend_latched(self, topic: str) -> int:
        """Send the kept messages of a latched topic again (a client subscribed to it after they
        were logged, as a transient-local subscriber would get them); returns how many."""
        entry = self.topics.get(topic)
        if entry is None:
            return 0
        for data, time_ns in list(entry.latched):
            entry.channel.log(data, log_time=time_ns)
        return len(entry.latched)

    def stop(self) -> None:
        """Close the channels and the server (clients see the connection end)."""
        _DROP_REPORTS.servers.discard(self)
        for entry in self.topics.values():
            entry.channel.close()
        self._server.stop()
