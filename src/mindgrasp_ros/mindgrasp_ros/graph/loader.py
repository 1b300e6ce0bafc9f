"""The Node subclass a graph's node names: ``pkg.mod`` (the one it defines) or ``pkg.mod:Class``.

A graph host constructs the class with keyword arguments only, as rclpy's ``Node`` takes them
(``cli_args``, ``parameter_overrides``, ``context``): a node class to be composed accepts
``**kwargs`` and forwards them, as in ros2/demos::

    class Talker(rclpy.node.Node):
        def __init__(self, **kwargs):
            super().__init__('talker', **kwargs)
"""

from __future__ import annotations

import importlib
import inspect

from mindgrasp_ros.errors import CompositionError

__all__ = ['check_composable', 'load_node_class']


def load_node_class(module_name: str) -> type:
    """The Node subclass defined in ``module_name``.

    Parameters
    ----------
    module_name : str
        ``pkg.mod`` (the module must define exactly one Node subclass) or ``pkg.mod:Class``.

    Returns
    -------
    type
        The class.

    Raises
    ------
    CompositionError
        The module does not import, or names no class, or more than one.
    """
    from mindgrasp_ros import rclpy

    module_name, _, class_name = module_name.partition(':')
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        msg = f'Cannot import node module {module_name!r}: {exc}'
        raise CompositionError(msg) from exc
    if class_name:
        try:
            return getattr(module, class_name)
        except AttributeError:
            msg = f'Module {module_name!r} has no class {class_name!r}.'
            raise CompositionError(msg) from None
    base = rclpy.node.Node
    classes = [obj for _n, obj in inspect.getmembers(module, inspect.isclass)
               if issubclass(obj, base) and obj is not base and obj.__module__ == module.__name__]
    if len(classes) != 1:
        names = ', '.join(c.__name__ for c in classes) or 'none'
        msg = (f'Module {module_name!r} must define exactly one Node subclass to be composed '
               f'(found: {names}); name it as "{module_name}:ClassName".')
        raise CompositionError(msg)
    return classes[0]


def check_composable(node_class: type, keywords: tuple[str, ...]) -> None:
    """Refuse a class whose ``__init__`` cannot take ``keywords`` (the host's arguments).

    Raises
    ------
    CompositionError
        Naming the class and the fix (accept ``**kwargs`` and forward them).
    """
    try:
        params = inspect.signature(node_class).parameters.values()
    except (TypeError, ValueError):
        return
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return
    names = {p.name for p in params if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)}
    missing = [k for k in keywords if k not in names]
    if missing:
        msg = (f'{node_class.__module__}.{node_class.__qualname__} cannot be composed: its '
               f'__init__ takes no {", ".join(missing)}; accept **kwargs and pass them on, '
               f"as in super().__init__('name', **kwargs).")
        raise CompositionError(msg)
