"""``LaunchDescription``, launch files (``*.launch.py``), profiles and includes."""

from __future__ import annotations

import importlib.util
import os
import sys
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from mindgrasp_common.resources import resource_path
from mindgrasp_launch.actions.action import Action
from mindgrasp_launch.actions.declare_launch_argument import DeclareLaunchArgument
from mindgrasp_launch.errors import LaunchError
from mindgrasp_launch.launch_api import own_launcher
from mindgrasp_launch.substitutions import (
    SomeSubstitutions,
    Substitution,
    perform_substitutions,
)

if TYPE_CHECKING:
    from mindgrasp_launch.context import LaunchContext

#: the profiles: mindgrasp_bringup/launch/<profile>.launch.py (share/mindgrasp_bringup/launch
#: in a colcon install)
PROFILE_DIR = resource_path('mindgrasp_bringup', 'launch')
LAUNCH_SUFFIX = '.launch.py'


class LaunchDescription(Action):
    """An ordered list of actions (``generate_launch_description()`` returns one)."""

    def __init__(self, initial_entities: Iterable[object] | None = None, **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        self.entities: list[object] = list(initial_entities or [])
        for entity in self.entities:
            _check_entity(entity)
        self.source: Path | None = None

    def add_action(self, action: object) -> None:
        """Append an action."""
        _check_entity(action)
        self.entities.append(action)

    add_entity = add_action

    def children(self) -> list[Action]:
        return [e for e in self.entities if isinstance(e, Action)]

    def execute(self, context: LaunchContext) -> None:
        visit_entities(self.entities, context)

    def get_launch_arguments(self) -> list[DeclareLaunchArgument]:
        """Every declared argument, included descriptions too, first declaration wins."""
        return list(collect_arguments(self).values())


def _check_entity(entity: object) -> None:
    if not isinstance(entity, Action):
        msg = (f'a launch description holds actions (Node, DeclareLaunchArgument, ...), not '
               f'{type(entity).__name__} {entity!r}.')
        raise LaunchError(msg)


def visit_entities(entities: Iterable[object], context: LaunchContext) -> None:
    """Execute actions in order."""
    for entity in entities:
        _check_entity(entity)
        entity.visit(context)  # type: ignore[attr-defined]


def profiles() -> list[str]:
    """Names of the launch profiles (``demo``, ``sim``, ...), sorted."""
    return sorted(p.name[:-len(LAUNCH_SUFFIX)] for p in PROFILE_DIR.glob('*' + LAUNCH_SUFFIX))


def find_launch_file(profile_or_path: str | Path) -> Path:
    """The launch file of a profile name or a path to a ``*.launch.py`` file."""
    text = str(profile_or_path)
    path = Path(text).expanduser()
    if text.endswith('.py') or path.is_file():
        if not path.is_file():
            msg = f'launch file {path} does not exist: check the path.'
            raise LaunchError(msg)
        return path.resolve()
    candidate = PROFILE_DIR / f'{text}{LAUNCH_SUFFIX}'
    if candidate.is_file():
        return candidate
    msg = (f"unknown launch profile '{text}': valid profiles are "
           f"{', '.join(profiles()) or '(none)'}, or give the path of a *.launch.py file.")
    raise LaunchError(msg)


_CACHE: dict[tuple[Path, float, str], LaunchDescription] = {}


def load_launch_file(path: str | Path) -> LaunchDescription:
    """Import a launch file and call its ``generate_launch_description()``."""
    path = find_launch_file(path)
    # a description lists the parameter files of $MINDGRASP_PARAMS_FILES when it is generated
    # (launch_system.params.config_files): a session's phases in one process each name theirs
    key = (path, path.stat().st_mtime, os.environ.get('MINDGRASP_PARAMS_FILES', ''))
    if key in _CACHE:
        return _CACHE[key]
    module_name = 'mindgrasp_launch_file_' + ''.join(c if c.isalnum() else '_'
                                                     for c in str(path))
    spec = importlib.util.spec_from_file_location(module_name, path)
    if spec is None or spec.loader is None:
        msg = f'launch file {path} cannot be loaded as Python: name it <name>.launch.py.'
        raise LaunchError(msg)
    module = importlib.util.module_from_spec(spec)
    sys.modules[module_name] = module
    try:
        with own_launcher():  # the file's launch_api imports resolve to our actions
            spec.loader.exec_module(module)
    except LaunchError:
        raise
    except Exception as exc:
        msg = f'launch file {path} failed to import: {type(exc).__name__}: {exc}'
        raise LaunchError(msg) from exc
    generate = getattr(module, 'generate_launch_description', None)
    if generate is None:
        msg = f'launch file {path} has no generate_launch_description() function; add one.'
        raise LaunchError(msg)
    try:
        with own_launcher():
            description = generate()
    except LaunchError:
        raise
    except Exception as exc:
        msg = f'generate_launch_description() of {path} raised {type(exc).__name__}: {exc}'
        raise LaunchError(msg) from exc
    if not isinstance(description, LaunchDescription):
        msg = (f'generate_launch_description() of {path} returned '
               f'{type(description).__name__}, not a LaunchDescription.')
        raise LaunchError(msg)
    description.source = path
    _CACHE[key] = description
    return description


class PythonLaunchDescriptionSource:
    """A Python launch file to include (path, profile name or substitutions)."""

    def __init__(self, launch_file_path: SomeSubstitutions) -> None:
        self.location = launch_file_path


class IncludeLaunchDescription(Action):
    """Include another launch description, passing it launch arguments.

    ``IncludeLaunchDescription('sim', launch_arguments={'gui': 'false'})``; the source may be a
    profile name, a path, substitutions, a ``PythonLaunchDescriptionSource`` or a
    ``LaunchDescription``. The included description sees the including one's configurations;
    what it sets does not leak back.
    """

    def __init__(self, launch_description_source: object, *,
                 launch_arguments: Mapping[str, SomeSubstitutions] | Iterable | None = None,
                 **kwargs: object) -> None:
        super().__init__(**kwargs)  # type: ignore[arg-type]
        if isinstance(launch_description_source, PythonLaunchDescriptionSource):
            launch_description_source = launch_description_source.location
        self.source = launch_description_source
        items = (launch_arguments.items() if isinstance(launch_arguments, Mapping)
                 else launch_arguments or [])
        self.launch_arguments = [(str(k), v) for k, v in items]

    def _description(self, context: LaunchContext | None) -> LaunchDescription:
        if isinstance(self.source, LaunchDescription):
            return self.source
        if context is None:
            if isinstance(self.source, (Substitution, list)):
                raise LaunchError('include source needs a context')
            location = str(self.source)
        else:
            location = perform_substitutions(context, self.source)  # type: ignore[arg-type]
        if (context is not None and context.launch_file is not None
                and location.endswith('.py') and not Path(location).is_absolute()
                and not Path(location).exists()):
            location = str(context.launch_file.parent / location)
        return load_launch_file(location)

    def children(self) -> list[Action]:
        try:
            return [self._description(None)]
        except LaunchError:
            return []

    def execute(self, context: LaunchContext) -> None:
        description = self._description(context)
        name = str(description.source or 'inline description')
        if name in context.include_stack:
            chain = ' -> '.join([*context.include_stack, name])
            msg = f'launch files include each other in a cycle: {chain}; break the cycle.'
            raise LaunchError(msg)
        inner = context.scoped()
        inner.include_stack.append(name)
        for key, value in self.launch_arguments:
            inner.launch_configurations[key] = perform_substitutions(context, value)
        if description.source is not None:
            inner.launch_file = description.source
        description.visit(inner)


def collect_arguments(action: Action) -> dict[str, DeclareLaunchArgument]:
    """Declared arguments of a description tree, walked without resolving conditions."""
    found: dict[str, DeclareLaunchArgument] = {}
    seen: set[int] = set()

    def walk(node: Action) -> None:
        if id(node) in seen:
            return
        seen.add(id(node))
        if isinstance(node, DeclareLaunchArgument):
            found.setdefault(node.name, node)
        for child in node.children():
            walk(child)

    walk(action)
    return found
