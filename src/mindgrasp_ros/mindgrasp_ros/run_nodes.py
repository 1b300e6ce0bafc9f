"""The nodes a run directory records, with the traits their classes declare.

``launch.yaml`` of a run lists its processes (``label``, ``node``: the fully qualified node
name, ``module``: the node's Python module); the report tools ask the node classes what a node
is (:class:`~mindgrasp_ros.node_traits.NodeTraits`: the prompter, the parameter naming the task,
the parameter setting a topic's rate) instead of knowing nodes by name::

    for node in run_nodes(run_dir):
        if node.traits.task_parameter: ...
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from mindgrasp_ros.node_traits import NodeTraits, traits_of

__all__ = ['RunNode', 'run_nodes']


@dataclass(frozen=True)
class RunNode:
    """One node of a run.

    Attributes
    ----------
    label
        The run's label of the node (its ``params/<label>.yaml`` and log).
    name
        Fully qualified node name (``/classifier``), the section of ``params.yaml``.
    traits
        What its class declares (the defaults when its module no longer loads: an old
        run still reads).
    """

    label: str
    name: str
    traits: NodeTraits


def run_nodes(run_dir: str | Path) -> list[RunNode]:
    """The nodes ``run_dir/launch.yaml`` lists (none without the file or a readable list)."""
    import yaml

    from mindgrasp_ros.errors import CompositionError
    from mindgrasp_ros.graph.loader import load_node_class

    try:
        launch = yaml.safe_load((Path(run_dir) / 'launch.yaml').read_text(encoding='utf-8'))
    except (OSError, yaml.YAMLError):
        return []
    out = []
    for item in (launch or {}).get('processes') or []:
        if not isinstance(item, dict) or not item.get('module'):
            continue
        try:
            traits = traits_of(load_node_class(str(item['module'])))
        except (CompositionError, TypeError):
            traits = traits_of(object)
        label = str(item.get('label', ''))
        out.append(RunNode(label, str(item.get('node') or f'/{label}'), traits))
    return out
