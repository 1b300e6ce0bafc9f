"""Message and service classes by package: ``mindgrasp_ros.interfaces.<package>.msg|srv``.

``from mindgrasp_ros.interfaces.sensor_msgs.msg import JointState`` mirrors
``from sensor_msgs.msg import JointState``. With ``MINDGRASP_RMW=rclpy`` the module *is* the
ROS-generated ``sensor_msgs.msg``; otherwise it is built from the runtime's typestore
(:mod:`mindgrasp_ros.typesupport`). An import hook creates these modules on first use.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types

from mindgrasp_ros import using_real_rclpy

_PREFIX = __name__ + '.'


def _packages() -> set[str]:
    from mindgrasp_ros.typesupport import typestore

    return {name.split('/')[0] for name in typestore().fielddefs}


class _InterfaceFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Creates ``<prefix><package>`` and ``<prefix><package>.msg|srv`` modules on demand."""

    def find_spec(self, fullname, path, target=None):
        if not fullname.startswith(_PREFIX):
            return None
        parts = fullname[len(_PREFIX):].split('.')
        if len(parts) > 2 or (len(parts) == 2 and parts[1] not in ('msg', 'srv')):
            return None
        is_package = len(parts) == 1
        return importlib.machinery.ModuleSpec(fullname, self, is_package=is_package)

    def create_module(self, spec):
        parts = spec.name[len(_PREFIX):].split('.')
        if using_real_rclpy():  # pragma: no cover - needs ROS 2
            return importlib.import_module('.'.join(parts))
        if parts[0] not in _packages():
            msg = (f'No interface package {parts[0]!r}. Known: {", ".join(sorted(_packages()))}.'
                   ' Custom messages belong in src/mindgrasp_msgs/msg/.')
            raise ModuleNotFoundError(msg, name=spec.name)
        module = types.ModuleType(spec.name)
        if len(parts) == 1:
            module.__path__ = []  # a package, so .msg/.srv can be imported below it
        else:
            module.__getattr__ = _module_getattr(parts[0], parts[1])  # type: ignore[attr-defined]
            module.__all__ = _names(parts[0], parts[1])  # type: ignore[attr-defined]
        return module

    def exec_module(self, module):
        pass


def _names(package: str, kind: str) -> list[str]:
    from mindgrasp_ros.typesupport import typestore

    names = set()
    for full in typestore().fielddefs:
        pkg, k, name = full.split('/')
        if pkg == package and k == kind:
            names.add(name.removesuffix('_Request').removesuffix('_Response') if k == 'srv'
                      else name)
    return sorted(names)


def _module_getattr(package: str, kind: str):
    from mindgrasp_ros.typesupport import (
        MessageTypeError,
        get_message_class,
        get_service_class,
    )

    def __getattr__(name: str):  # noqa: N807
        if name.startswith('__'):
            raise AttributeError(name)
        try:
            if kind == 'msg':
                return get_message_class(f'{package}/msg/{name}')
            return get_service_class(f'{package}/srv/{name}')
        except MessageTypeError as exc:
            raise ImportError(str(exc)) from None

    return __getattr__


if not any(isinstance(f, _InterfaceFinder) for f in sys.meta_path):
    sys.meta_path.insert(0, _InterfaceFinder())
