"""A graph of nodes as data, and the one host that runs it.

* :mod:`.spec`: :class:`NodeSpec`, one node of a graph (module, name, typed parameters, remaps),
  and the arguments that build it as rclpy's ``Node`` takes them.
* :mod:`.loader`: :func:`load_node_class`, the Node subclass a spec names.
* :mod:`.lockstep`: :class:`LockstepRunner`, a DDS-less process on a clock the caller advances.
* :mod:`.host`: :class:`GraphRunner` under a scheduler (:class:`Lockstep`, :class:`InProcess`,
  :class:`Processes`) and :func:`run_composed`.

The modules import one another in that order only (spec -> loader; lockstep -> spec, loader;
host -> spec, loader, lockstep). The names below load their module when first asked, so
``from mindgrasp_ros.graph import NodeSpec`` does not load the runtime.
"""

from __future__ import annotations

import importlib
from typing import Any

__all__ = ['CompositionError', 'GraphRunner', 'InProcess', 'Lockstep', 'LockstepRunner',
           'NodeCallbackError', 'NodeSpec', 'ProcessHandle', 'Processes', 'Scheduler',
           'load_node_class', 'run_composed']

_WHERE = {
    'NodeSpec': 'spec', 'load_node_class': 'loader', 'LockstepRunner': 'lockstep',
    'GraphRunner': 'host', 'InProcess': 'host', 'Lockstep': 'host', 'ProcessHandle': 'host',
    'Processes': 'host', 'Scheduler': 'host', 'run_composed': 'host',
}


def __getattr__(name: str) -> Any:
    if name in ('CompositionError', 'NodeCallbackError'):
        from mindgrasp_ros import errors

        return getattr(errors, name)
    if name in _WHERE:
        return getattr(importlib.import_module(f'{__name__}.{_WHERE[name]}'), name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
