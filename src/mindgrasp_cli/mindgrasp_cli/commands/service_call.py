"""Call a service with a request given as YAML (like ``ros2 service call``).

    mindgrasp service call /sim/reset mindgrasp_msgs/srv/ResetSim "{seed: 7}"

Prints ``requester: making request: ...`` and ``response: ...`` as ros2 does. Unlike ros2, which
waits for ever, a service that does not appear within ``--timeout`` seconds ends the command with
one line and exit code 1 (a typo in the name must not hang a script).
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any

import yaml

from mindgrasp_cli.ros_cli import CliError, UsageError, cli_node, print_error, set_fields
from mindgrasp_common.cli_checks import positive_float


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('service_name', help="name of the service, e.g. '/sim/reset'")
    parser.add_argument('service_type', help="type of the service, e.g. 'std_srvs/srv/Empty'")
    group = parser.add_mutually_exclusive_group()
    group.add_argument('values', nargs='?', default='{}',
                       help="YAML of the request fields, e.g. '{seed: 7}' (default: all defaults)")
    group.add_argument('--stdin', action='store_true', help='read the values from standard input')
    parser.add_argument('-r', '--rate', metavar='N', type=positive_float,
                        help='repeat the call at this rate (Hz) until Ctrl-C')
    parser.add_argument('--timeout', type=positive_float, default=10.0,
                        help='seconds to wait for the service to appear (default 10)')


def build_request(service_type: str, values: str) -> tuple[Any, Any]:
    """``(service class, filled Request)``; a :class:`UsageError` names a bad type or field."""
    from mindgrasp_ros.typesupport import MessageTypeError, get_service_class

    parts = service_type.split('/')
    if len(parts) == 2:   # 'pkg/Name', as ros2 accepts it
        parts = [parts[0], 'srv', parts[1]]
    if len(parts) != 3 or parts[1] != 'srv' or not all(parts):
        msg = f'{service_type!r} is not a service type; write it as "package/srv/Name".'
        raise UsageError(msg)
    try:
        srv = get_service_class('/'.join(parts))
    except MessageTypeError as exc:
        raise UsageError(str(exc)) from None
    try:
        fields = yaml.safe_load(values)
    except yaml.YAMLError as exc:
        problem = ' '.join(str(exc).split())
        msg = f'The values are not valid YAML ({problem}); e.g. "{{seed: 7}}".'
        raise UsageError(msg) from None
    if fields is None:
        fields = {}
    if not isinstance(fields, dict):
        raise UsageError(f'The values must be a YAML mapping of request fields, not {values!r}.')
    try:
        request = set_fields(srv.Request(), fields)
    except CliError as exc:
        raise UsageError(str(exc)) from None
    return srv, request


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros import rclpy

    try:
        values = sys.stdin.read() if args.stdin else args.values
        srv, request = build_request(args.service_type, values)
        with cli_node('requester') as node:
            client = node.create_client(srv, args.service_name)
            if not client.service_is_ready():
                print('waiting for service to become available...', flush=True)
                if not client.wait_for_service(timeout_sec=args.timeout):
                    msg = (f"Service '{args.service_name}' did not appear within "
                           f'{args.timeout:g} s; check the name with `mindgrasp service list` '
                           'and the ROS_DOMAIN_ID.')
                    raise CliError(msg)
            while True:
                print(f'requester: making request: {request!r}\n', flush=True)
                last_call = time.monotonic()
                future = client.call_async(request)
                rclpy.spin_until_future_complete(node, future)
                if future.result() is None:
                    raise CliError(f'The call of {args.service_name} failed: '
                                   f'{future.exception()!r}')
                print(f'response:\n{future.result()!r}\n', flush=True)
                if args.rate is None or not rclpy.ok():
                    break
                time.sleep(max(0.0, last_call + 1.0 / args.rate - time.monotonic()))
    except CliError as exc:
        return print_error(exc)
    return 0
