"""ROS names: validation, expansion (``~``, relative names) and remapping, as rcl does it."""

from __future__ import annotations

import re
from dataclasses import dataclass

from mindgrasp_ros.runtime.exceptions import InvalidNameError

__all__ = ['RemapRule', 'apply_remaps', 'expand_topic_name', 'validate_namespace',
           'validate_node_name', 'validate_topic_name']

_NODE_RE = re.compile(r'^[A-Za-z_][A-Za-z0-9_]*$')
_TOKEN_RE = re.compile(r'^[A-Za-z_][A-Za-z0-9_]*$|^\{[A-Za-z_][A-Za-z0-9_]*\}$')


def validate_node_name(name: str) -> str:
    if not name or not _NODE_RE.match(name) or len(name) > 255:
        msg = (f'Invalid node name {name!r}: use letters, digits and underscores, not starting '
               'with a digit (e.g. "eeg_acquisition").')
        raise InvalidNameError(msg)
    return name


def validate_namespace(namespace: str) -> str:
    """Validate and normalise a namespace ('' and 'ns' become '/' and '/ns')."""
    if namespace in ('', '/'):
        return '/'
    ns = namespace if namespace.startswith('/') else '/' + namespace
    ns = ns.rstrip('/')
    for token in ns.split('/')[1:]:
        if not _NODE_RE.match(token):
            msg = (f'Invalid namespace {namespace!r}: each part must be letters, digits and '
                   'underscores, not starting with a digit (e.g. "/trainer_robot").')
            raise InvalidNameError(msg)
    return ns


def validate_topic_name(name: str, *, is_service: bool = False) -> str:
    what = 'service' if is_service else 'topic'
    if not name:
        msg = f'Invalid {what} name: it is empty.'
        raise InvalidNameError(msg)
    body = name
    if body.startswith('~'):
        body = body[1:]
        if body and not body.startswith('/'):
            msg = f"Invalid {what} name {name!r}: '~' must be followed by '/' or nothing."
            raise InvalidNameError(msg)
    body = body.lstrip('/')
    if name.endswith('/') and name not in ('/', '~/'):
        msg = f'Invalid {what} name {name!r}: it must not end with "/".'
        raise InvalidNameError(msg)
    if '//' in name:
        msg = f'Invalid {what} name {name!r}: it must not contain "//".'
        raise InvalidNameError(msg)
    for token in body.split('/') if body else []:
        if not _TOKEN_RE.match(token):
            msg = (f'Invalid {what} name {name!r}: part {token!r} must be letters, digits and '
                   'underscores, not starting with a digit (e.g. "/eeg/raw").')
            raise InvalidNameError(msg)
    return name


def expand_topic_name(name: str, node_name: str, namespace: str) -> str:
    """Fully qualified name: ``~`` is the node's private namespace, relative names join the
    node's namespace, ``{node}``/``{ns}`` substitutions as in rcl."""
    validate_topic_name(name)
    ns = validate_namespace(namespace)
    name = name.replace('{node}', node_name).replace('{ns}', ns.rstrip('/') or '')
    if name.startswith('~'):
        base = f'{ns.rstrip("/")}/{node_name}'
        name = base + name[1:]
    elif not name.startswith('/'):
        name = f'{ns.rstrip("/")}/{name}'
    return name


@dataclass(frozen=True)
class RemapRule:
    """``[node:]from:=to``; ``from`` may be ``__node`` or ``__ns``."""

    from_: str
    to: str
    node: str | None = None

    @classmethod
    def parse(cls, text: str) -> RemapRule:
        if ':=' not in text:
            msg = f'Invalid remapping {text!r}: write it as "from:=to" or "node:from:=to".'
            raise InvalidNameError(msg)
        lhs, to = text.split(':=', 1)
        node = None
        if ':' in lhs:
            node, lhs = lhs.split(':', 1)
        if not lhs or not to:
            msg = f'Invalid remapping {text!r}: both sides of ":=" are needed.'
            raise InvalidNameError(msg)
        return cls(lhs, to, node)

    def applies_to(self, node_name: str) -> bool:
        return self.node is None or self.node == node_name


def apply_remaps(name: str, rules: list[RemapRule], node_name: str, namespace: str) -> str:
    """Remap an expanded topic/service name with the first matching rule (rcl semantics)."""
    for rule in rules:
        if rule.from_ in ('__node', '__name', '__ns') or not rule.applies_to(node_name):
            continue
        if expand_topic_name(rule.from_, node_name, namespace) == name:
            return expand_topic_name(rule.to, node_name, namespace)
    return name
