"""``rclpy.node.Node``: names, publishers, subscriptions, timers, services, parameters, logging,
clock and graph queries, with rclpy's signatures."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from mindgrasp_ros.runtime import logging as rlog
from mindgrasp_ros.runtime.callback_groups import (
    CallbackGroup,
    MutuallyExclusiveCallbackGroup,
)
from mindgrasp_ros.runtime.client import Client
from mindgrasp_ros.runtime.clock import Clock, ROSClock
from mindgrasp_ros.runtime.context import Context
from mindgrasp_ros.runtime.entity import Entity
from mindgrasp_ros.runtime.exceptions import (
    InvalidParameterTypeException,
    InvalidParameterValueException,
    NotInitializedException,
    ParameterAlreadyDeclaredException,
    ParameterNotDeclaredException,
    ParameterUninitializedException,
)
from mindgrasp_ros.runtime.guard_condition import GuardCondition
from mindgrasp_ros.runtime.names import (
    apply_remaps,
    expand_topic_name,
    validate_namespace,
    validate_node_name,
)
from mindgrasp_ros.runtime.parameter import Parameter, parameter_value_to_python
from mindgrasp_ros.runtime.publisher import Publisher
from mindgrasp_ros.runtime.qos import (
    QoSProfile,
    as_profile,
    qos_profile_clock,
    qos_profile_parameter_events,
    qos_profile_rosout_default,
    qos_profile_services_default,
)
from mindgrasp_ros.runtime.service import Service
from mindgrasp_ros.runtime.subscription import Subscription
from mindgrasp_ros.runtime.timer import Timer
from mindgrasp_ros.runtime.utilities import get_default_context
from mindgrasp_ros.typesupport import get_message_class, get_service_class, normalize_type_name

if TYPE_CHECKING:
    from mindgrasp_ros.runtime.executors import Executor

__all__ = ['Node']


def _interfaces(name: str) -> type:
    return get_message_class(f'rcl_interfaces/msg/{name}')


class Node:
    """A ROS 2 node (see rclpy.node.Node)."""

    PARAM_REL_TOL = 1e-6

    def __init__(self, node_name: str, *, context: Context | None = None,
                 cli_args: list[str] | None = None, namespace: str | None = None,
                 use_global_arguments: bool = True, enable_rosout: bool = True,
                 start_parameter_services: bool = True,
                 parameter_overrides: list[Parameter] | None = None,
                 allow_undeclared_parameters: bool = False,
                 automatically_declare_parameters_from_overrides: bool = False) -> None:
        from mindgrasp_ros.runtime.arguments import RosArguments, parse_ros_args

        self.context = context or get_default_context()
        # what wake_executor collected for take_ready_entities: True means look at every entity
        self._changed = True
        self._ready_entities: dict[Entity, None] = {}   # in arrival order, each once
        if not self.context.ok():
            raise NotInitializedException('context')
        args = RosArguments()
        if use_global_arguments:
            args.extend(self.context.args)
        if cli_args:
            args.extend(parse_ros_args(['--ros-args', *cli_args]
                                       if '--ros-args' not in cli_args else cli_args))
        self._args = args
        validate_node_name(node_name)
        self._name = validate_node_name(args.node_name_override(node_name) or node_name)
        ns = args.namespace_override(node_name) or namespace or '/'
        self._namespace = validate_namespace(ns)
        self._logger = rlog.get_logger(self._logger_name())
        self._lock = threading.RLock()
        self.default_callback_group: CallbackGroup = MutuallyExclusiveCallbackGroup()
        self.callback_groups = [self.default_callback_group]
        self.publishers: list[Publisher] = []
        self.subscriptions: list[Subscription] = []
        self.timers: list[Timer] = []
        self.services: list[Service] = []
        self.clients: list[Client] = []
        self.guards: list[GuardCondition] = []
        self.generation = 0  # bumped when entities change, so executors re-scan
        self.executor: Executor | None = None
        self._destroyed = False

        # parameters
        self._parameters: dict[str, Parameter] = {}
        self._descriptors: dict[str, Any] = {}
        self._set_callbacks: list[Callable] = []
        self._allow_undeclared = allow_undeclared_parameters
        self._overrides: dict[str, Any] = dict(args.parameters_for(self._name, self._namespace))
        for p in parameter_overrides or []:   # typed values win over the arguments' (rclpy)
            self._overrides[p.name] = p.value

        self.context.add_node(self)
        self._clock = ROSClock()
        self._clock_sub: Subscription | None = None
        self._rosout_pub: Publisher | None = None
        self._param_events_pub = self.create_publisher(
            _interfaces('ParameterEvent'), '/parameter_events', qos_profile_parameter_events)
        if enable_rosout:
            self._rosout_pub = self.create_publisher(
                _interfaces('Log'), '/rosout', qos_profile_rosout_default)
            rlog.add_sink(self._rosout_sink)
        self.declare_parameter('use_sim_time', False)
        self._apply_use_sim_time(self.get_parameter('use_sim_time').value)
        self.add_on_set_parameters_callback(self._on_use_sim_time)
        if automatically_declare_parameters_from_overrides:
            for name, value in self._overrides.items():
                if name not in self._parameters:
                    self.declare_parameter(name, value)
        if start_parameter_services:
            self._start_parameter_services()
        self.context.publish_discovery_info()

    # ------------------------------------------------------------------ names
    def _logger_name(self) -> str:
        ns = self._namespace.strip('/').replace('/', '.')
        return f'{ns}.{self._name}' if ns else self._name

    def get_name(self) -> str:
        return self._name

    def get_namespace(self) -> str:
        return self._namespace

    def get_fully_qualified_name(self) -> str:
        return f'{self._namespace.rstrip("/")}/{self._name}'

    def resolve_topic_name(self, topic: str, *, only_expand: bool = False) -> str:
        expanded = expand_topic_name(topic, self._name, self._namespace)
        if only_expand:
            return expanded
        return apply_remaps(expanded, self._args.remaps, self._name, self._namespace)

    def resolve_service_name(self, service: str, *, only_expand: bool = False) -> str:
        return self.resolve_topic_name(service, only_expand=only_expand)

    def get_logger(self) -> rlog.RcutilsLogger:
        return self._logger

    def get_clock(self) -> Clock:
        return self._clock

    @property
    def handle(self) -> Node:
        return self

    # ------------------------------------------------------------------ executor hooks
    def wake_executor(self, entity: Entity | None = None) -> None:
        """Tell the executor that ``entity`` got in-process work (a delivery, a request, a
        trigger), or with None that the node's entities changed."""
        if entity is None:
            self._changed = True
        else:
            self._ready_entities[entity] = None
        executor = self.executor
        if executor is not None:
            executor.wake()

    def take_ready_entities(self) -> list[Entity] | None:
        """The entities that got in-process work since the last call, in the order executors
        take them (:attr:`Entity.take_order`); None when the entities changed since (look at
        every one). For executors that run without a wait set (lock-step): a node with a dozen
        services (the parameter services) gets work for one subscription in most rounds."""
        if self._changed:
            self._changed = False
            self._ready_entities.clear()
            return None
        if not self._ready_entities:
            return []
        ready = list(self._ready_entities)
        self._ready_entities.clear()
        if len(ready) > 1:
            ready.sort(key=_take_order)
        return ready

    def _add(self, collection: list, entity: Entity) -> Any:
        with self._lock:
            collection.append(entity)
            self.generation += 1
        self.context.publish_discovery_info()
        self.wake_executor()
        return entity

    def _remove(self, collection: list, entity: Entity) -> bool:
        with self._lock:
            if entity not in collection:
                return False
            collection.remove(entity)
            self.generation += 1
            self._ready_entities.pop(entity, None)
        entity.destroy()
        self.context.publish_discovery_info()
        return True

    def dds_gids(self) -> tuple[list[bytes], list[bytes]]:
        """DDS GUIDs of this node's readers and writers (for ros_discovery_info)."""
        readers: list[bytes] = []
        writers: list[bytes] = []
        with self._lock:
            for s in self.subscriptions:
                if s.dds_reader is not None:
                    readers.append(s.gid)
            for p in self.publishers:
                if p.on_dds:
                    writers.append(p.gid)
            for srv in self.services:
                if srv.dds_reader is not None:
                    readers.append(srv.gid)
                    writers.append(srv.reply_gid)
            for cli in self.clients:
                if cli.dds_reader is not None:
                    writers.append(cli.gid)
                    readers.append(cli.reply_gid)
        return readers, writers

    # ------------------------------------------------------------------ entities
    def _resolve_type(self, msg_type: type | str) -> tuple[type, str]:
        if isinstance(msg_type, str):
            name = normalize_type_name(msg_type)
            return get_message_class(name), name
        from mindgrasp_ros.typesupport import type_name_of

        return msg_type, type_name_of(msg_type)

    def create_publisher(self, msg_type: type | str, topic: str,
                         qos_profile: QoSProfile | int, *,
                         callback_group: CallbackGroup | None = None,
                         event_callbacks: object = None,
                         qos_overriding_options: object = None,
                         publisher_class: object = None,
                         raw: bool = False) -> Publisher:
        """Publisher of ``msg_type`` (a class or ``'pkg/msg/Name'``); ``raw=True`` publishes
        CDR bytes too."""
        cls, name = self._resolve_type(msg_type)
        resolved = self.resolve_topic_name(topic)
        pub = Publisher(self, cls, resolved, as_profile(qos_profile), callback_group, raw=raw,
                        type_name=name)
        return self._add(self.publishers, pub)

    def create_subscription(self, msg_type: type | str, topic: str, callback: Callable,
                            qos_profile: QoSProfile | int, *,
                            callback_group: CallbackGroup | None = None,
                            event_callbacks: object = None,
                            qos_overriding_options: object = None,
                            raw: bool = False, polled: bool = False) -> Subscription:
        """Subscription; ``raw=True`` hands the callback CDR bytes (with the 4-byte header).

        ``polled=True`` (this runtime only, not rclpy): no executor waits for it or calls
        ``callback``; the node reads what has arrived with ``subscription.take()``, e.g. from a
        timer. A node that forwards many topics (the live view) then wakes once per period
        instead of once per message, at a fraction of the CPU.
        """
        cls, name = self._resolve_type(msg_type)
        resolved = self.resolve_topic_name(topic)
        sub = Subscription(self, cls, resolved, callback, as_profile(qos_profile),
                           callback_group, raw=raw, type_name=name, polled=polled)
        return self._add(self.subscriptions, sub)

    def create_timer(self, timer_period_sec: float, callback: Callable | None,
                     callback_group: CallbackGroup | None = None, clock: Clock | None = None,
                     autostart: bool = True) -> Timer:
        timer = Timer(self, timer_period_sec, callback, callback_group, clock or self._clock,
                      autostart)
        return self._add(self.timers, timer)

    def create_rate(self, frequency: float, clock: Clock | None = None):
        from mindgrasp_ros.runtime.rate import Rate

        return Rate(frequency, clock or self._clock)

    def create_guard_condition(self, callback: Callable,
                               callback_group: CallbackGroup | None = None) -> GuardCondition:
        return self._add(self.guards, GuardCondition(self, callback, callback_group))

    def _srv_class(self, srv_type: type | str) -> type:
        return get_service_class(srv_type) if isinstance(srv_type, str) else srv_type

    def create_service(self, srv_type: type | str, srv_name: str, callback: Callable, *,
                       qos_profile: QoSProfile = qos_profile_services_default,
                       callback_group: CallbackGroup | None = None) -> Service:
        srv = Service(self, self._srv_class(srv_type), self.resolve_service_name(srv_name),
                      callback, qos_profile, callback_group)
        return self._add(self.services, srv)

    def create_client(self, srv_type: type | str, srv_name: str, *,
                      qos_profile: QoSProfile = qos_profile_services_default,
                      callback_group: CallbackGroup | None = None) -> Client:
        cli = Client(self, self._srv_class(srv_type), self.resolve_service_name(srv_name),
                     qos_profile, callback_group)
        return self._add(self.clients, cli)

    def destroy_publisher(self, publisher: Publisher) -> bool:
        return self._remove(self.publishers, publisher)

    def destroy_subscription(self, subscription: Subscription) -> bool:
        return self._remove(self.subscriptions, subscription)

    def destroy_timer(self, timer: Timer) -> bool:
        return self._remove(self.timers, timer)

    def destroy_service(self, service: Service) -> bool:
        return self._remove(self.services, service)

    def destroy_client(self, client: Client) -> bool:
        return self._remove(self.clients, client)

    def destroy_guard_condition(self, guard: GuardCondition) -> bool:
        return self._remove(self.guards, guard)

    def context_shutdown(self) -> None:
        """Called by the context when it ends: the node is dead; its DDS entities go with
        the participant."""
        self._destroyed = True
        rlog.remove_sink(self._rosout_sink)

    def destroy_node(self) -> None:
        if self._destroyed:
            return
        self._destroyed = True
        rlog.remove_sink(self._rosout_sink)
        if self.executor is not None:
            self.executor.remove_node(self)
        if self.context.ok():
            for collection in (self.subscriptions, self.publishers, self.timers, self.services,
                               self.clients, self.guards):
                for entity in list(collection):
                    with self._lock:
                        collection.remove(entity)
                    entity.destroy()
        self.context.remove_node(self)

    # ------------------------------------------------------------------ logging
    def _rosout_sink(self, severity: rlog.LoggingSeverity, name: str, message: str, file: str,
                     function: str, line: int) -> None:
        if name != self._logger.name and not name.startswith(self._logger.name + '.'):
            return
        pub = self._rosout_pub
        if pub is None or not self.context.ok():
            return
        pub.publish(_interfaces('Log')(
            stamp=self._clock.now().to_msg(), level=int(severity), name=name, msg=message,
            file=file, function=function, line=line))

    # ------------------------------------------------------------------ time
    def _apply_use_sim_time(self, enabled: bool) -> None:
        if enabled and self._clock_sub is None:
            self._clock.set_ros_time_override_ns(0)
            self._clock_sub = self.create_subscription(
                get_message_class('rosgraph_msgs/msg/Clock'), '/clock', self._on_clock,
                qos_profile_clock)
        elif not enabled and self._clock_sub is not None:
            self.destroy_subscription(self._clock_sub)
            self._clock_sub = None
            self._clock.set_ros_time_override_ns(None)

    def _on_clock(self, msg: Any) -> None:
        self._clock.set_ros_time_override_ns(
            int(msg.clock.sec) * 1_000_000_000 + int(msg.clock.nanosec))

    def _on_use_sim_time(self, params: list[Parameter]) -> Any:
        for p in params:
            if p.name == 'use_sim_time' and p.type_ != Parameter.Type.BOOL:
                return _interfaces('SetParametersResult')(
                    successful=False, reason='use_sim_time must be a bool')
                # applied after acceptance, below in _set_parameter_unchecked
        return _interfaces('SetParametersResult')(successful=True)

    # ------------------------------------------------------------------ parameters
    def declare_parameter(self, name: str, value: Any = None,
                          descriptor: Any = None, ignore_override: bool = False) -> Parameter:
        """Declare a parameter; an override (file or ``-p``) replaces the default.

        ``value`` may be a default value or a :class:`Parameter.Type` for a parameter that
        must be given (statically typed, uninitialised until set)."""
        if not name or not isinstance(name, str):
            raise InvalidParameterValueException(str(name), value, 'invalid parameter name')
        if name in self._parameters:
            raise ParameterAlreadyDeclaredException(name)
        desc = descriptor or _interfaces('ParameterDescriptor')()
        desc.name = name
        declared_type: Parameter.Type | None = None
        if isinstance(value, Parameter.Type):
            declared_type, value = value, None
        elif isinstance(value, Parameter):
            value = value.value
        elif type(value).__name__ == 'ParameterValue':
            # rclpy accepts an rcl_interfaces/ParameterValue: its type field gives the type,
            # which an empty list alone cannot
            declared_type, value = Parameter.Type(value.type), parameter_value_to_python(value)
        if declared_type is None and value is not None:
            # the default's type is the parameter's type; an int override of a float
            # default stays a float (rclpy would silently make it an int)
            try:
                declared_type = Parameter.Type.from_parameter_value(value)
            except TypeError as exc:
                raise InvalidParameterValueException(name, value, str(exc)) from None
        if not ignore_override and name in self._overrides:
            value = self._overrides[name]
        try:
            inferred = Parameter.Type.from_parameter_value(value)
        except TypeError as exc:
            raise InvalidParameterValueException(name, value, str(exc)) from None
        if declared_type is None:
            declared_type = inferred
        if value is not None and not declared_type.check(value):
            if declared_type == Parameter.Type.DOUBLE and inferred == Parameter.Type.INTEGER:
                value = float(value)
            elif not desc.dynamic_typing:
                raise InvalidParameterTypeException(Parameter(name, value=value), declared_type)
        if value is None:
            param = Parameter(name, Parameter.Type.NOT_SET, None)
        elif declared_type.check(value):
            param = Parameter(name, declared_type, value)
        else:
            param = Parameter(name, value=value)
        desc.type = int(declared_type)
        self._check_range(param, desc)
        if value is not None:
            result = self._call_set_callbacks([param])
            if not result.successful:
                raise InvalidParameterValueException(name, value, result.reason)
        self._descriptors[name] = desc
        self._parameters[name] = param
        self._publish_param_event(new=[param])
        return param

    def declare_parameters(self, namespace: str, parameters: Sequence[tuple],
                           ignore_override: bool = False) -> list[Parameter]:
        out = []
        for item in parameters:
            name = f'{namespace}.{item[0]}' if namespace else item[0]
            value = item[1] if len(item) > 1 else None
            descriptor = item[2] if len(item) > 2 else None
            out.append(self.declare_parameter(name, value, descriptor, ignore_override))
        return out

    def undeclare_parameter(self, name: str) -> None:
        if name not in self._parameters:
            raise ParameterNotDeclaredException(name)
        if self._descriptors[name].read_only:
            msg = f"Parameter '{name}' is read-only and cannot be undeclared."
            raise InvalidParameterValueException(name, None, msg)
        param = self._parameters.pop(name)
        self._descriptors.pop(name)
        self._publish_param_event(deleted=[param])

    def has_parameter(self, name: str) -> bool:
        return name in self._parameters

    def get_parameter(self, name: str) -> Parameter:
        if name in self._parameters:
            param = self._parameters[name]
            desc_type = Parameter.Type(self._descriptors[name].type)
            if param.type_ == Parameter.Type.NOT_SET and desc_type != Parameter.Type.NOT_SET:
                raise ParameterUninitializedException(name)
            return param
        if self._allow_undeclared:
            return Parameter(name, Parameter.Type.NOT_SET, None)
        raise ParameterNotDeclaredException(name)

    def get_parameter_or(self, name: str, alternative_value: Parameter | None = None) -> Parameter:
        if name in self._parameters:
            return self._parameters[name]
        return alternative_value or Parameter(name, Parameter.Type.NOT_SET, None)

    def get_parameters(self, names: list[str]) -> list[Parameter]:
        return [self.get_parameter(n) for n in names]

    def get_parameters_by_prefix(self, prefix: str) -> dict[str, Parameter]:
        pre = f'{prefix}.' if prefix else ''
        return {k[len(pre):]: v for k, v in self._parameters.items() if k.startswith(pre)}

    def describe_parameter(self, name: str) -> Any:
        if name not in self._descriptors:
            raise ParameterNotDeclaredException(name)
        return self._descriptors[name]

    def describe_parameters(self, names: list[str]) -> list[Any]:
        return [self.describe_parameter(n) for n in names]

    def add_on_set_parameters_callback(self, callback: Callable) -> None:
        self._set_callbacks.insert(0, callback)

    def remove_on_set_parameters_callback(self, callback: Callable) -> None:
        self._set_callbacks.remove(callback)

    def set_parameters(self, parameter_list: list[Parameter]) -> list[Any]:
        return [self._set_parameters_atomically([p]) for p in parameter_list]

    def set_parameters_atomically(self, parameter_list: list[Parameter]) -> Any:
        return self._set_parameters_atomically(parameter_list)

    def _check_range(self, param: Parameter, desc: Any) -> None:
        value = param.value
        if param.type_ == Parameter.Type.DOUBLE and len(desc.floating_point_range):
            r = desc.floating_point_range[0]
            if not r.from_value - self.PARAM_REL_TOL <= value <= r.to_value + self.PARAM_REL_TOL:
                raise InvalidParameterValueException(
                    param.name, value, f'must be within [{r.from_value}, {r.to_value}]')
        if param.type_ == Parameter.Type.INTEGER and len(desc.integer_range):
            r = desc.integer_range[0]
            if not r.from_value <= value <= r.to_value:
                raise InvalidParameterValueException(
                    param.name, value, f'must be within [{r.from_value}, {r.to_value}]')

    def _call_set_callbacks(self, params: list[Parameter]) -> Any:
        result_cls = _interfaces('SetParametersResult')
        for cb in list(self._set_callbacks):
            result = cb(params)
            if result is None or not getattr(result, 'successful', False):
                return result or result_cls(successful=False, reason='rejected by a callback')
        return result_cls(successful=True)

    def _set_parameters_atomically(self, params: list[Parameter]) -> Any:
        result_cls = _interfaces('SetParametersResult')
        staged = []
        for p in params:
            if p.name not in self._parameters:
                if not self._allow_undeclared:
                    return result_cls(successful=False,
                                      reason=f"parameter '{p.name}' is not declared")
                staged.append(p)
                continue
            desc = self._descriptors[p.name]
            if desc.read_only:
                return result_cls(successful=False,
                                  reason=f"parameter '{p.name}' is read-only: restart the node "
                                  'with the new value to change it')
            declared = Parameter.Type(desc.type)
            value = p.value
            if (declared != Parameter.Type.NOT_SET and p.type_ != declared
                    and not desc.dynamic_typing):
                if declared == Parameter.Type.DOUBLE and p.type_ == Parameter.Type.INTEGER:
                    p = Parameter(p.name, Parameter.Type.DOUBLE, float(value))
                else:
                    return result_cls(
                        successful=False,
                        reason=f"wrong parameter type for '{p.name}': expected "
                               f'{declared.name}, got {p.type_.name}')
            try:
                self._check_range(p, desc)
            except InvalidParameterValueException as exc:
                return result_cls(successful=False, reason=str(exc))
            staged.append(p)
        result = self._call_set_callbacks(staged)
        if not result.successful:
            return result
        new, changed = [], []
        for p in staged:
            (changed if p.name in self._parameters else new).append(p)
            if p.name not in self._descriptors:
                self._descriptors[p.name] = _interfaces('ParameterDescriptor')(
                    name=p.name, type=int(p.type_))
            self._parameters[p.name] = p
            if p.name == 'use_sim_time':
                self._apply_use_sim_time(bool(p.value))
        self._publish_param_event(new=new, changed=changed)
        return result

    def _publish_param_event(self, new: Sequence[Parameter] = (),
                             changed: Sequence[Parameter] = (),
                             deleted: Sequence[Parameter] = ()) -> None:
        pub = getattr(self, '_param_events_pub', None)
        if pub is None or not self.context.ok():
            return
        pub.publish(_interfaces('ParameterEvent')(
            stamp=self._clock.now().to_msg(), node=self.get_fully_qualified_name(),
            new_parameters=[p.to_parameter_msg() for p in new],
            changed_parameters=[p.to_parameter_msg() for p in changed],
            deleted_parameters=[p.to_parameter_msg() for p in deleted]))

    def _start_parameter_services(self) -> None:
        from mindgrasp_ros.runtime.parameter_service import ParameterService

        self._parameter_service = ParameterService(self)

    # ------------------------------------------------------------------ graph
    def get_node_names(self) -> list[str]:
        return [n for n, _ns in self.get_node_names_and_namespaces()]

    def get_node_names_and_namespaces(self) -> list[tuple[str, str]]:
        return self.context.graph.node_names_and_namespaces()

    def get_topic_names_and_types(self, no_demangle: bool = False) -> list[tuple[str, list[str]]]:
        return self.context.graph.topic_names_and_types()

    def get_service_names_and_types(self) -> list[tuple[str, list[str]]]:
        return self.context.graph.service_names_and_types()

    def get_publishers_info_by_topic(self, topic_name: str, no_mangle: bool = False) -> list:
        return self.context.graph.endpoints(self.resolve_topic_name(topic_name), 'publisher')

    def get_subscriptions_info_by_topic(self, topic_name: str, no_mangle: bool = False) -> list:
        return self.context.graph.endpoints(self.resolve_topic_name(topic_name), 'subscription')

    def count_publishers(self, topic_name: str) -> int:
        return len(self.get_publishers_info_by_topic(topic_name))

    def count_subscribers(self, topic_name: str) -> int:
        return len(self.get_subscriptions_info_by_topic(topic_name))

    def __repr__(self) -> str:
        return f'<Node {self.get_fully_qualified_name()}>'


def _take_order(entity: Entity) -> tuple[int, int]:
    return entity.take_order
