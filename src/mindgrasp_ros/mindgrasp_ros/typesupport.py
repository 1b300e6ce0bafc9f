"""Type support: the message/service registry, rclpy-like message classes and CDR (de)serialisation.

One typestore holds every type the runtime knows: ROS 2 Jazzy's common_interfaces (from the
``rosbags`` Jazzy store), the service types the runtime serves (rcl_interfaces parameter services,
std_srvs, moveit_msgs/srv/ServoCommandType), and ``mindgrasp_msgs`` registered from its own
``msg/*.msg`` and ``srv/*.srv`` files, so the interface package is the one source of truth.

Message classes behave like rclpy's generated classes: keyword construction with ROS defaults,
numeric sequences as numpy arrays, ``get_fields_and_field_types()``. Serialisation uses ``rosbags``'
generated numpy CDR code (XCDR1, little endian), which reads attributes by name, so our classes
are passed to it directly and it constructs our classes when deserialising.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import keyword
import os
import threading
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.base import Nodetype
from rosbags.typesys.msg import get_types_from_msg
from rosbags.typesys.store import Typestore

from mindgrasp_common.resources import ResourceNotFoundError, resource_path
from mindgrasp_ros.errors import RosError

__all__ = [
    'EMPTY_PLACEHOLDER',
    'MessageTypeError',
    'deserialize',
    'get_message_class',
    'get_service_class',
    'rihs01',
    'serialize',
    'type_name_of',
    'typestore',
]


class MessageTypeError(RosError):
    """An unknown message type, or a message of the wrong class."""



_NUMPY_DTYPES = {
    'bool': np.bool_, 'byte': np.uint8, 'char': np.uint8, 'int8': np.int8, 'uint8': np.uint8,
    'int16': np.int16, 'uint16': np.uint16, 'int32': np.int32, 'uint32': np.uint32,
    'int64': np.int64, 'uint64': np.uint64, 'float32': np.float32, 'float64': np.float64,
}
_PY_DEFAULTS = {'bool': False, 'float32': 0.0, 'float64': 0.0, 'string': ''}

#: Field defaults that ROS .msg files declare but rosbags' field definitions do not carry.
_FIELD_DEFAULTS: dict[str, dict[str, Any]] = {
    'geometry_msgs/msg/Quaternion': {'w': 1.0},
}

#: Service types the runtime needs beyond the rosbags store (which has no srv types); MoveIt
#: Servo's switch_command_type is served by the simulator and called by the controller.
_EXTRA_SERVICE_FILES = ('moveit_msgs', 'rcl_interfaces', 'std_srvs')

#: the member rosidl gives a message without fields; not a field of rclpy's Python classes
EMPTY_PLACEHOLDER = 'structure_needs_at_least_one_member'

_lock = threading.RLock()


def _split_srv(text: str) -> tuple[str, str]:
    lines = text.splitlines()
    for i, line in enumerate(lines):
        if line.strip() == '---':
            return '\n'.join(lines[:i]), '\n'.join(lines[i + 1:])
    msg = 'A .srv definition needs a line "---" between request and response.'
    raise MessageTypeError(msg)


def _register_srv(store: Typestore, package: str, name: str, text: str) -> None:
    request, response = _split_srv(text)
    for part, body in (('Request', request), ('Response', response)):
        # Parse under a msg name (the parser resolves relative names against the package),
        # then register under the srv name.
        parsed = get_types_from_msg(body, f'{package}/msg/{name}_{part}')
        store.register({f'{package}/srv/{name}_{part}': v for v in parsed.values()})


def _register_interface_dir(store: Typestore, package: str, folder: Path) -> None:
    msg_dir = folder / 'msg'
    pending: dict[str, str] = {}
    if msg_dir.is_dir():
        for path in sorted(msg_dir.glob('*.msg')):
            pending[f'{package}/msg/{path.stem}'] = path.read_text(encoding='utf-8')
    types: dict[str, Any] = {}
    for name, text in pending.items():
        types.update(get_types_from_msg(text, name))
    if types:
        store.register(types)
    srv_dir = folder / 'srv'
    if srv_dir.is_dir():
        for path in sorted(srv_dir.glob('*.srv')):
            _register_srv(store, package, path.stem, path.read_text(encoding='utf-8'))


def interface_dir() -> Path:
    """Folder of the ``mindgrasp_msgs`` interface package (``msg/``, ``srv/``, package.xml).

    In order: ``MINDGRASP_MSGS_DIR``; ``interface_data/mindgrasp_msgs`` of this package, a link
    to the interface package ``src/mindgrasp_msgs`` (installs copy it); ``share/mindgrasp_msgs`` of
    a sourced colcon workspace (``AMENT_PREFIX_PATH``), where rosidl installs the ``.msg``/``.srv``
    files. The source folder is deliberately not a Python package, so that with ROS 2 sourced
    ``import mindgrasp_msgs.msg`` finds the colcon-generated package, not this folder.
    """
    override = os.environ.get('MINDGRASP_MSGS_DIR')
    if override:
        candidates = [Path(override)]
    else:
        candidates = []
        with contextlib.suppress(ResourceNotFoundError):
            candidates.append(resource_path('mindgrasp_ros', 'interface_data', 'mindgrasp_msgs'))
        candidates += [Path(prefix) / 'share' / 'mindgrasp_msgs'
                       for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep)
                       if prefix]
    for folder in candidates:
        if (folder / 'msg').is_dir():
            return folder
    msg = (f'The mindgrasp_msgs interface folder was not found (looked in '
           f'{", ".join(str(c) for c in candidates)}); install the project editable '
           '(pip install -e .), build mindgrasp_msgs in your colcon workspace, or set '
           'MINDGRASP_MSGS_DIR to src/mindgrasp_msgs.')
    raise MessageTypeError(msg)


@functools.cache
def typestore() -> Typestore:
    """The process-wide typestore: Jazzy common_interfaces, service types and mindgrasp_msgs.

    Message classes of this store are this module's rclpy-like classes, so
    ``typestore().deserialize_cdr(raw, 'sensor_msgs/msg/JointState')`` returns one of them.
    Bag tools use the same store to read and write rosbag2 files.
    """
    store = get_typestore(Stores.ROS2_JAZZY)
    # A copy of the types table: we replace the classes below, never the shared store's.
    store.types = dict(store.types)
    store.cache = {}
    for package in _EXTRA_SERVICE_FILES:
        _register_interface_dir(store, package, resource_path('mindgrasp_ros', 'interface_data',
                                                              package))
    _register_interface_dir(store, 'mindgrasp_msgs', interface_dir())
    for name in list(store.fielddefs):
        store.types[name] = _make_message_class(store, name)
    return store


# --------------------------------------------------------------------------- message classes


def _constant(value: Any) -> Any:
    return value


class _NestedDefault:
    """Default of a nested message field: a new message of its class, looked up once (the class
    may not exist yet when the enclosing class is made)."""

    __slots__ = ('cls', 'typename')

    def __init__(self, typename: str) -> None:
        self.typename = typename
        self.cls: type[Message] | None = None

    def __call__(self) -> Message:
        if self.cls is None:
            self.cls = get_message_class(self.typename)
        return self.cls()


def _field_default_factory(desc: tuple) -> Any:
    kind, detail = desc
    if kind == Nodetype.BASE:
        base, _bound = detail
        return functools.partial(_constant, _PY_DEFAULTS.get(base, 0))
    if kind == Nodetype.NAME:
        return _NestedDefault(detail)
    (sub_kind, sub_detail), count = detail
    if sub_kind == Nodetype.BASE and sub_detail[0] in _NUMPY_DTYPES:
        dtype = _NUMPY_DTYPES[sub_detail[0]]
        n = count if kind == Nodetype.ARRAY else 0
        return lambda: np.zeros(n, dtype=dtype)
    if kind == Nodetype.ARRAY:
        if sub_kind == Nodetype.BASE:
            return lambda: [''] * count
        return lambda: [get_message_class(sub_detail)() for _ in range(count)]
    return list


def _numeric_dtype(desc: tuple) -> tuple[Any, int | None] | None:
    """(dtype, fixed length or None) for numeric array/sequence fields, else None."""
    kind, detail = desc
    if kind not in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return None
    (sub_kind, sub_detail), count = detail
    if sub_kind != Nodetype.BASE or sub_detail[0] not in _NUMPY_DTYPES:
        return None
    return _NUMPY_DTYPES[sub_detail[0]], (count if kind == Nodetype.ARRAY else None)


def _ros_type_string(desc: tuple, msg_syntax: bool = False) -> str:
    """A field's type as ``get_fields_and_field_types`` gives it (``sequence<float64>``), or
    with ``msg_syntax`` as a ``.msg`` file writes it (``float64[]``, ``int32[<=5]``)."""
    kind, detail = desc
    if kind == Nodetype.BASE:
        base, bound = detail
        return f'{base}<={bound}' if bound else base
    if kind == Nodetype.NAME:
        return detail.replace('/msg/', '/')
    (sub, count) = detail
    inner = _ros_type_string(sub, msg_syntax)
    if kind == Nodetype.ARRAY:
        return f'{inner}[{count}]'
    if msg_syntax:
        return f'{inner}[<={count}]' if count else f'{inner}[]'
    return f'sequence<{inner}, {count}>' if count else f'sequence<{inner}>'


class Message:
    """Base class of runtime message classes (rclpy-like, see module docstring)."""

    __slots__ = ()
    __msgtype__: str = ''
    _fields: tuple[str, ...] = ()
    _defaults: tuple = ()
    _numeric: dict[str, tuple[Any, int | None]] = {}
    _fields_and_field_types: dict[str, str] = {}

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        fields = self._fields
        if args:
            if len(args) > len(fields):
                msg = f'{self.__msgtype__} takes at most {len(fields)} positional fields.'
                raise TypeError(msg)
            if not kwargs and len(args) == len(fields):
                # Fast path used by the deserialiser: values arrive complete and typed.
                for name, value in zip(fields, args, strict=True):
                    object.__setattr__(self, name, value)
                return
            kwargs = {**dict(zip(fields, args, strict=False)), **kwargs}
        if kwargs and not kwargs.keys() <= self._fields_and_field_types.keys():
            key = next(k for k in kwargs if k not in self._fields_and_field_types)
            msg = (f'{self.__msgtype__} has no field {key!r}; its fields are: '
                   f'{", ".join(fields)}.')
            raise TypeError(msg)
        # Messages are built at every publish: one pass over the fields, numeric ones converted
        # (as __setattr__ does), the others stored as given or as their default.
        numeric = self._numeric
        for name, factory in zip(fields, self._defaults, strict=True):
            if name in kwargs:
                value = kwargs[name]
                spec = numeric.get(name)
                if spec is not None:
                    value = _as_array(self.__msgtype__, name, value, *spec)
                object.__setattr__(self, name, value)
            else:
                object.__setattr__(self, name, factory())

    def __setattr__(self, name: str, value: Any) -> None:
        spec = self._numeric.get(name)
        if spec is not None:
            value = _as_array(self.__msgtype__, name, value, *spec)
        object.__setattr__(self, name, value)

    @classmethod
    def get_fields_and_field_types(cls) -> dict[str, str]:
        """Field names and ROS IDL types, like rclpy's generated classes."""
        return dict(cls._fields_and_field_types)

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        for name in self._fields:
            a, b = getattr(self, name), getattr(other, name)
            if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
                if not np.array_equal(np.asarray(a), np.asarray(b)):
                    return False
            elif a != b:
                return False
        return True

    __hash__ = None  # mutable, like rclpy messages

    def __repr__(self) -> str:
        parts = []
        for name in self._fields:
            value = getattr(self, name)
            if isinstance(value, np.ndarray) and value.size > 16:
                text = f'array(shape={value.shape}, dtype={value.dtype})'
            else:
                text = repr(value)
            parts.append(f'{name}={text}')
        return f'{type(self).__module__}.{type(self).__qualname__}({", ".join(parts)})'


def _as_array(typename: str, field: str, value: Any, dtype: Any,
              length: int | None) -> np.ndarray:
    if isinstance(value, np.ndarray) and value.dtype == dtype and value.ndim == 1:
        arr = value
    elif isinstance(value, (bytes, bytearray, memoryview)) and dtype == np.uint8:
        arr = np.frombuffer(value, dtype=np.uint8)
    else:
        try:
            arr = np.asarray(value, dtype=dtype)
        except (TypeError, ValueError) as exc:
            msg = f'{typename}.{field} must be a sequence of {np.dtype(dtype).name}: {exc}'
            raise TypeError(msg) from None
        if arr.ndim != 1:
            arr = arr.reshape(-1)
    if length is not None and arr.shape[0] != length:
        msg = f'{typename}.{field} must have exactly {length} elements, not {arr.shape[0]}.'
        raise ValueError(msg)
    return arr


def _make_message_class(store: Typestore, typename: str) -> type[Message]:
    consts, fields = store.fielddefs[typename]
    package, kind, name = typename.split('/')
    field_names = tuple(_normalize(f) for f, _ in fields)
    defaults = []
    extra = _FIELD_DEFAULTS.get(typename, {})
    for fname, desc in fields:
        if fname in extra:
            defaults.append(functools.partial(_constant, extra[fname]))
        else:
            defaults.append(_field_default_factory(desc))
    namespace: dict[str, Any] = {
        '__slots__': field_names,
        '__msgtype__': typename,
        '__module__': f'{package}.{kind}',
        '__qualname__': name,
        '_fields': field_names,
        '_defaults': tuple(defaults),
        '_numeric': {_normalize(f): spec for f, d in fields if (spec := _numeric_dtype(d))},
        '_fields_and_field_types': {_normalize(f): _ros_type_string(d) for f, d in fields},
    }
    if not namespace['_numeric']:
        # nothing to convert: plain slot assignment, as fast as a generated rclpy class
        namespace['__setattr__'] = object.__setattr__
    namespace['__init__'] = _keyword_init(typename, field_names, namespace['_defaults'],
                                          namespace['_numeric'])
    for cname, _ctype, value in consts:
        namespace[cname] = value
    return type(name, (Message,), namespace)


_MISSING = object()
_IMMUTABLE = (bool, int, float, str, bytes)


def _keyword_init(typename: str, fields: tuple[str, ...], defaults: tuple,
                  numeric: dict[str, tuple[Any, int | None]]) -> Any:
    """``__init__`` of one message class, written out field by field as rosidl writes the
    generated Python classes: the node graph builds hundreds of messages per simulated second,
    and the generic :meth:`Message.__init__` loop costs twice as much. Positional arguments and
    unknown names take the generic path (the same result and errors).

    The source is made from the field names of the message definition only (ROS field names
    are identifiers: letters, digits and underscores), never from user text.
    """
    glb: dict[str, Any] = {'_m_set': object.__setattr__, '_m_missing': _MISSING,
                           '_m_generic': Message.__init__, '_m_as_array': _as_array,
                           '_m_type': typename}
    params, lines = [], []
    for i, (name, factory) in enumerate(zip(fields, defaults, strict=True)):
        if not name.isidentifier() or name.startswith('_m_'):
            return Message.__init__      # not a ROS field name: no code made from it
        params.append(f'{name}=_m_missing')
        if isinstance(factory, functools.partial) and isinstance(factory.args[0], _IMMUTABLE):
            glb[f'_m_d{i}'] = factory.args[0]
            default = f'_m_d{i}'
        else:
            glb[f'_m_d{i}'] = factory
            default = f'_m_d{i}()'
        value = name
        if name in numeric:
            glb[f'_m_s{i}'] = numeric[name]
            value = f"_m_as_array(_m_type, '{name}', {name}, *_m_s{i})"
        lines.append(f"    _m_set(_m_self, '{name}', {default} if {name} is _m_missing "
                     f'else {value})')
    # a ROS message has at least one field (an empty .msg gets structure_needs_at_least_one_member)
    given = ''.join(f"('{name}', {name}), " for name in fields)
    src = '\n'.join([
        f"def __init__(_m_self, *_m_args, {', '.join(params)}, **_m_extra):",
        '    if _m_args or _m_extra:',
        f'        _m_kw = {{k: v for k, v in ({given}) if v is not _m_missing}}',
        '        _m_generic(_m_self, *_m_args, **_m_kw, **_m_extra)',
        '        return',
        *lines,
    ])
    exec(compile(src, f'<{typename} __init__>', 'exec'), glb)     # names only: see docstring
    return glb['__init__']


def _normalize(name: str) -> str:
    return f'{name}_' if keyword.iskeyword(name) else name


class Service:
    """Base class of runtime service classes: ``Srv.Request`` and ``Srv.Response``."""

    __srvtype__: str = ''
    Request: type[Message]
    Response: type[Message]


@functools.cache
def get_service_class(srvtype: str) -> type[Service]:
    """The service class of ``'pkg/srv/Name'`` (``Request`` and ``Response`` attributes)."""
    store = typestore()
    req, res = f'{srvtype}_Request', f'{srvtype}_Response'
    if req not in store.types or res not in store.types:
        raise MessageTypeError(_unknown_type_message(srvtype, 'srv'))
    package, _, name = srvtype.split('/')
    return type(name, (Service,), {
        '__srvtype__': srvtype, '__module__': f'{package}.srv', '__qualname__': name,
        'Request': store.types[req], 'Response': store.types[res],
    })


def _unknown_type_message(typename: str, kind: str) -> str:
    store = typestore()
    package = typename.split('/')[0]
    known = sorted({n.split('/')[0] for n in store.fielddefs})
    same = sorted({n.rsplit('/', 1)[-1].removesuffix('_Request').removesuffix('_Response')
                   for n in store.fielddefs if n.startswith(f'{package}/{kind}/')})
    hint = (f' Known {package} {kind} types: {", ".join(same)}.' if same
            else f' Known packages: {", ".join(known)}.')
    return (f'Unknown {kind} type {typename!r}.{hint} Custom types belong in '
            f'src/mindgrasp_msgs/{kind}/ (registered at start-up).')


def get_message_class(typename: str) -> type[Message]:
    """The message class of ``'pkg/msg/Name'`` (``'pkg/Name'`` is accepted too)."""
    typename = normalize_type_name(typename)
    store = typestore()
    try:
        return store.types[typename]  # type: ignore[return-value]
    except KeyError:
        raise MessageTypeError(_unknown_type_message(typename, 'msg')) from None


def normalize_type_name(typename: str) -> str:
    """``'pkg/Name'`` -> ``'pkg/msg/Name'``; ``'pkg/msg/Name'`` unchanged."""
    parts = typename.split('/')
    if len(parts) == 2:
        return f'{parts[0]}/msg/{parts[1]}'
    if len(parts) != 3 or not all(parts):
        msg = f'{typename!r} is not a ROS type name; write it as "package/msg/Name".'
        raise MessageTypeError(msg)
    return typename


def type_name_of(msg_type: type | object) -> str:
    """ROS type name (``'pkg/msg/Name'``) of a message class or instance, ours or rclpy's."""
    cls = msg_type if isinstance(msg_type, type) else type(msg_type)
    name = getattr(cls, '__msgtype__', None)
    if name:
        return name
    # rclpy generated classes: module 'sensor_msgs.msg._joint_state', class 'JointState'
    module = cls.__module__.split('.')
    if len(module) >= 2 and module[1] in ('msg', 'srv'):
        return f'{module[0]}/{module[1]}/{cls.__name__}'
    msg = f'{cls!r} is not a ROS message class.'
    raise MessageTypeError(msg)


def serialize(msg: object, typename: str | None = None) -> bytes:
    """CDR bytes (4-byte encapsulation header, little endian) of a message."""
    name = typename or type_name_of(msg)
    return bytes(typestore().serialize_cdr(msg, name, little_endian=True))


def deserialize(data: bytes | memoryview, typename: str) -> Message:
    """Message from CDR bytes (with the encapsulation header)."""
    return typestore().deserialize_cdr(data, typename)  # type: ignore[return-value]


# --------------------------------------------------------------------------- RIHS01 type hashes

_TYPE_IDS = {
    'int8': 2, 'uint8': 3, 'int16': 4, 'uint16': 5, 'int32': 6, 'uint32': 7, 'int64': 8,
    'uint64': 9, 'float32': 10, 'float64': 11, 'float128': 12,
    # rosidl maps .msg "char" to uint8 in type descriptions (rosbags says 13, which is wrong).
    'char': 3, 'bool': 15, 'byte': 16, 'string': 17, 'bounded_string': 21,
}


@functools.cache
def rihs01(typename: str) -> str:
    """REP-2011 type hash ``RIHS01_<sha256>`` of a message type, as rosidl computes it."""
    store = typestore()
    structs: dict[str, dict] = {}

    def field(name: str, desc: tuple) -> dict:
        increment = capacity = string_capacity = 0
        nested = ''
        kind, detail = desc
        if kind == Nodetype.ARRAY:
            increment, capacity = 48, detail[1]
            kind, detail = detail[0]
        elif kind == Nodetype.SEQUENCE:
            bound = detail[1]
            increment, capacity = (96, bound) if bound else (144, 0)
            kind, detail = detail[0]
        if kind == Nodetype.NAME:
            tid = increment + 1
            nested = detail
            struct(detail)
        elif detail[0] == 'string' and detail[1]:
            string_capacity = detail[1]
            tid = increment + _TYPE_IDS['bounded_string']
        else:
            tid = increment + _TYPE_IDS[detail[0]]
        return {'name': name, 'type': {'type_id': tid, 'capacity': capacity,
                                       'string_capacity': string_capacity,
                                       'nested_type_name': nested}}

    def struct(name: str) -> dict:
        if name not in structs:
            fields = store.fielddefs[name][1] or [
                ('structure_needs_at_least_one_member', (Nodetype.BASE, ('uint8', 0)))]
            structs[name] = {'type_name': name, 'fields': [field(n, d) for n, d in fields]}
        return structs[name]

    top = struct(normalize_type_name(typename))
    desc = {'type_description': top,
            'referenced_type_descriptions': [v for k, v in sorted(structs.items())
                                             if k != typename]}
    return 'RIHS01_' + hashlib.sha256(json.dumps(desc).encode()).hexdigest()


def message_definition(typename: str) -> str:
    """Full ros2msg definition text with dependencies, as rosbag2 stores it in MCAP schemas."""
    text, _digest = typestore().generate_msgdef(typename, ros_version=2)
    return text
