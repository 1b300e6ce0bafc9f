"""Shared helpers of the ``topic``, ``node`` and ``param`` commands (the ``ros2`` CLI's verbs).

They work against any ROS 2 graph on the domain: endpoints come from DDS discovery and node
names from ``ros_discovery_info`` (see :mod:`mindgrasp_ros.runtime.dds.discovery`).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
from collections.abc import Iterator
from typing import Any

import numpy as np
import yaml

from mindgrasp_ros.typesupport import EMPTY_PLACEHOLDER

__all__ = ['CliError', 'UsageError', 'cli_node', 'find_topic_type', 'is_hidden_name',
           'message_to_yaml', 'message_type', 'node_name', 'print_names_and_types',
           'resolve_field', 'set_fields', 'topic_name', 'wait_for_graph']


class CliError(Exception):
    """A command-line error with a message for the user (exit code 1)."""


class UsageError(CliError):
    """The command's own input is wrong (a name, a type, a value that does not fit its field),
    found before anything is sent: exit code 2, like argparse."""


def is_hidden_name(name: str) -> bool:
    """A topic or service name with a token that starts with ``_`` (rcl's hidden names, which
    ``ros2 service list`` leaves out unless ``--include-hidden-services``)."""
    return any(token.startswith('_') for token in name.split('/'))


# argparse ``type=`` checks of names and types: a bad one is a usage error (one line, exit 2)
# before any DDS traffic, instead of a traceback from the node that would have used it

def topic_name(text: str) -> str:
    """A valid ROS topic name (``/eeg/raw``, ``eeg/raw``, ``~/out``)."""
    from mindgrasp_ros.runtime.exceptions import InvalidNameError
    from mindgrasp_ros.runtime.names import validate_topic_name

    try:
        return validate_topic_name(text)
    except InvalidNameError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def node_name(text: str) -> str:
    """A valid node name, fully qualified (``/fsm``, ``/trainer_robot/sim``) or relative."""
    from mindgrasp_ros.runtime.exceptions import InvalidNameError
    from mindgrasp_ros.runtime.names import validate_namespace, validate_node_name

    namespace, _, name = text.rpartition('/')
    try:
        if '//' in text:
            raise InvalidNameError(f'Invalid node name {text!r}: it must not contain "//".')
        validate_namespace(namespace)
        validate_node_name(name)
    except InvalidNameError as exc:
        msg = f'{exc} Node names look like /fsm or /trainer_robot/sim (mindgrasp node list).'
        raise argparse.ArgumentTypeError(msg) from None
    return text


def message_type(text: str) -> str:
    """A message type the runtime knows (``std_msgs/msg/String`` or ``std_msgs/String``)."""
    from mindgrasp_ros.typesupport import MessageTypeError, get_message_class

    try:
        get_message_class(text)
    except MessageTypeError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


@contextlib.contextmanager
def cli_node(name: str = 'mindgrasp_cli') -> Iterator[Any]:
    """An initialised context and a hidden-ish node for one CLI invocation."""
    from mindgrasp_ros import rclpy

    rclpy.init(args=[])
    node = rclpy.node.Node(f'_{name}_{os.getpid()}', start_parameter_services=False,
                           enable_rosout=False)
    try:
        yield node
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def wait_for_graph(node: Any, settle_s: float = 1.0, max_s: float = 3.0) -> None:
    """Let discovery run until the set of topics stops changing (at most ``max_s``)."""
    start = time.monotonic()
    last: list = []
    stable_since = time.monotonic()
    while time.monotonic() - start < max_s:
        now = (node.get_topic_names_and_types() + node.get_service_names_and_types()
               + [tuple(x) for x in node.get_node_names_and_namespaces()])
        if now != last:
            last, stable_since = now, time.monotonic()
        elif time.monotonic() - stable_since >= settle_s:
            return
        time.sleep(0.1)


def print_names_and_types(items: list[tuple[str, list[str]]], show_types: bool,
                          count: bool) -> None:
    """Print topics or services as ``ros2 topic|service list`` does: the count (``-c``), or one
    name a line, with ``[type, ...]`` after it (``-t``)."""
    if count:
        print(len(items))
        return
    for name, types in items:
        print(f'{name} [{", ".join(types)}]' if show_types else name)


def find_topic_type(node: Any, topic: str, timeout_s: float = 5.0) -> str:
    """The type of ``topic`` as discovered on the graph; error when unknown."""
    deadline = time.monotonic() + timeout_s
    while True:
        types = dict(node.get_topic_names_and_types())
        if topic in types:
            if len(types[topic]) > 1:
                msg = (f"Topic '{topic}' has more than one type on the graph "
                       f'({", ".join(types[topic])}); pass --type to choose.')
                raise CliError(msg)
            return types[topic][0]
        if time.monotonic() >= deadline:
            known = ', '.join(sorted(types)) or 'none'
            msg = (f"Topic '{topic}' was not found on ROS_DOMAIN_ID="
                   f'{os.environ.get("ROS_DOMAIN_ID", "0")} within {timeout_s:.0f} s. Known '
                   f'topics: {known}. Check the name (mindgrasp topic list) and the domain.')
            raise CliError(msg)
        time.sleep(0.1)


def to_plain(value: Any, truncate: int | None = 128) -> Any:
    """Message -> nested dicts/lists of plain values (long arrays truncated like ros2)."""
    if hasattr(value, '_fields'):   # an empty message's placeholder is no field to rclpy
        return {name: to_plain(getattr(value, name), truncate) for name in value._fields
                if name != EMPTY_PLACEHOLDER}
    if isinstance(value, np.ndarray):
        items = value.tolist()
    elif isinstance(value, (list, tuple)):
        items = [to_plain(v, truncate) for v in value]
    elif isinstance(value, (bytes, bytearray)):
        items = list(value)
    else:
        if isinstance(value, str) and truncate and len(value) > truncate:
            return value[:truncate] + '...'
        return value
    if truncate and len(items) > truncate:
        return [*items[:truncate], '...']
    return items


def message_to_yaml(msg: Any, truncate: int | None = 128) -> str:
    """YAML text of a message, as ``ros2 topic echo`` prints it."""
    plain = to_plain(msg, truncate)
    if not isinstance(plain, dict):
        return yaml.safe_dump(plain, default_flow_style=False).rstrip() + '\n'
    return yaml.safe_dump(plain, sort_keys=False, default_flow_style=False, width=100)


def resolve_field(msg: Any, path: str) -> Any:
    """``--field header.stamp`` -> the nested value; a clear error for unknown names."""
    value = msg
    for part in path.split('.'):
        fields = getattr(value, '_fields', ())
        if part not in fields:
            msg_ = (f"Field {part!r} of {path!r} does not exist; fields here: "
                    f'{", ".join(fields) or "none (not a message)"}.')
            raise CliError(msg_)
        value = getattr(value, part)
    return value


def set_fields(msg: Any, values: dict[str, Any]) -> Any:
    """Fill a message from a dict (YAML of ``topic pub``), recursively, naming bad fields."""
    from mindgrasp_ros.typesupport import get_message_class
    from mindgrasp_ros.value_ranges import check_value

    fields = msg.get_fields_and_field_types()
    for key, value in values.items():
        if key not in fields:
            text = (f'{msg.__msgtype__} has no field {key!r}; its fields are: '
                    f'{", ".join(fields)}.')
            raise UsageError(text)
        current = getattr(msg, key)
        if hasattr(current, '_fields'):
            if not isinstance(value, dict):
                text = (f'Field {key!r} is a {fields[key]} message: give its fields as a mapping, '
                        f'e.g. "{{{key}: {{...}}}}"; {value!r} is not one.')
                raise UsageError(text)
            set_fields(current, value)
        elif isinstance(current, list) and isinstance(value, list) and value and \
                isinstance(value[0], dict):
            sub = fields[key].removeprefix('sequence<').split(',')[0].rstrip('>').split('[')[0]
            pkg, name = sub.split('/')
            cls = get_message_class(f'{pkg}/msg/{name}')
            setattr(msg, key, [set_fields(cls(), v) for v in value])
        else:
            try:
                check_value(f'{msg.__msgtype__} field {key!r}', fields[key], value)
                setattr(msg, key, value)
            except (TypeError, ValueError, OverflowError) as exc:
                raise UsageError(str(exc)) from None
    return msg


def print_error(exc: Exception) -> int:
    """Print ``exc`` as the command's one error line; the exit code (2 for a
    :class:`UsageError`, else 1)."""
    print(f'mindgrasp: {exc}', file=sys.stderr)
    return 2 if isinstance(exc, UsageError) else 1
