"""List the interface types this installation knows (like ``ros2 interface list``).

    mindgrasp interface list -s
"""

from __future__ import annotations

import argparse

HEADINGS = {'msg': 'Messages:', 'srv': 'Services:', 'action': 'Actions:'}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('-m', '--only-msgs', action='store_true',
                        help='print out only the message types')
    parser.add_argument('-s', '--only-srvs', action='store_true',
                        help='print out only the service types')
    parser.add_argument('-a', '--only-actions', action='store_true',
                        help='print out only the action types')


def main(args: argparse.Namespace) -> int:
    from mindgrasp_ros.interface_text import interface_names

    names = interface_names()
    chosen = [kind for kind, flag in (('msg', args.only_msgs), ('srv', args.only_srvs),
                                      ('action', args.only_actions)) if flag] or list(HEADINGS)
    for kind in chosen:
        print(HEADINGS[kind])
        for name in names[kind]:
            print(f'    {name}')
    return 0
