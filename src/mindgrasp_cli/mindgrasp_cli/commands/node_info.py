"""Publishers, subscribers and services of a node (like ``ros2 node info``)."""

from __future__ import annotations

import argparse

from mindgrasp_cli.ros_cli import cli_node, node_name, print_error, wait_for_graph


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('node', type=node_name, help='fully qualified node name, e.g. /sim')


def main(args: argparse.Namespace) -> int:
    ns, _, name = args.node.rpartition('/')
    ns = ns or '/'
    with cli_node() as node:
        wait_for_graph(node)
        if (name, ns) not in node.get_node_names_and_namespaces():
            # hidden nodes (_name, as this command's own) are left out, as node list does
            known = ', '.join(f'{n_ns.rstrip("/")}/{n}'
                              for n, n_ns in node.get_node_names_and_namespaces()
                              if not n.startswith('_')) or 'none'
            return print_error(Exception(f'Node {args.node!r} was not found. Nodes: {known} '
                                         '(mindgrasp node list).'))
        endpoints = node.context.graph.node_endpoints(name, ns)
    print(args.node)
    for title, key in (('Subscribers', 'subscribers'), ('Publishers', 'publishers'),
                       ('Service Servers', 'services'), ('Service Clients', 'clients')):
        print(f'  {title}:')
        for topic, typename in endpoints.get(key, []):
            print(f'    {topic}: {typename}')
    return 0
