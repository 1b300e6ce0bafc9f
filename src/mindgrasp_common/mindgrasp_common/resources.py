"""Data files shipped with the MIndGrasp packages: the one way to find them.

Models are package data of the package that owns them (``mindgrasp_classifier/models/...``).
What a user edits is in the top-level ``config/`` of the checkout: the nodes' parameter files
(``config/param/``), the launch profiles' overlays (``config/profiles/``), scenes
(``config/scenes/``), session plans (``config/plans/``) and robot descriptions with their URDFs
(``config/robots/``, ``config/robots/urdf/``); a colcon build installs it as
``share/mindgrasp_bringup/config/``. Code
asks for both kinds the same way, by the package the file belongs to, found by
:func:`resource_path`::

    from mindgrasp_common.resources import resource_path
    fsm_yaml = resource_path('mindgrasp_fsm', 'param', 'fsm.yaml')     # config/param/fsm.yaml

Lookup order:

1. A colcon install (``ament_index_python`` when ROS 2 is sourced, else the workspace's
   ``AMENT_PREFIX_PATH``): the file under the package's share directory ``share/<package>/<parts>``
   (for config files, ``share/mindgrasp_bringup/config/...``).
2. Otherwise, config files in the checkout's ``config/`` and package data next to the Python
   package, through :mod:`importlib.resources` (source checkouts, editable installs).

Values given by users (parameters, command-line arguments) go through :func:`resolve_path`, which
also understands ROS ``package://<package>/<path>`` URIs, as URDF and RViz files write them
(``package://mindgrasp_sim/scenes/set_locations.yaml`` is ``config/scenes/set_locations.yaml``).
"""

from __future__ import annotations

import atexit
import contextlib
import importlib.resources
import importlib.util
import os
from pathlib import Path

from mindgrasp_common.errors import ResourceNotFoundError

__all__ = ['CONFIG_FOLDERS', 'CONFIG_PACKAGE', 'PACKAGE_URI', 'ResourceNotFoundError', 'config_dir',
           'resolve_path', 'resource_path']

#: prefix of ROS package URIs (``package://mindgrasp_sim/urdf/mindgrasp_arm.urdf``)
PACKAGE_URI = 'package://'

#: the package whose share directory holds ``config/`` in a colcon install (its setup.py puts it)
CONFIG_PACKAGE = 'mindgrasp_bringup'
#: (package, folder) -> the folder of ``config/`` that holds that package's files of that folder;
#: ``(CONFIG_PACKAGE, 'config')`` is config/ itself, as installed (``package://mindgrasp_bringup/
#: config/scenes/x.yaml``)
CONFIG_FOLDERS: dict[tuple[str, str], str] = {
    **{(f'mindgrasp_{name}', 'param'): 'param'
       for name in ('eeg', 'classifier', 'vision', 'fsm', 'sim', 'trainer')},
    (CONFIG_PACKAGE, 'param'): 'profiles',
    ('mindgrasp_sim', 'scenes'): 'scenes',
    ('mindgrasp_sim', 'robots'): 'robots',
    ('mindgrasp_sim', 'urdf'): 'robots/urdf',
    (CONFIG_PACKAGE, 'plans'): 'plans',
    (CONFIG_PACKAGE, 'config'): '',
}

# keeps files extracted from zipped packages alive until the interpreter exits
_extracted = contextlib.ExitStack()
atexit.register(_extracted.close)


def _share_dir(package: str) -> Path | None:
    """``share/<package>`` of a colcon install: asked of ament_index when ROS 2 is sourced, else
    found as ament_index finds it, by the package's marker in a prefix of ``AMENT_PREFIX_PATH``
    (a sourced workspace of our packages without ROS 2)."""
    try:
        from ament_index_python.packages import PackageNotFoundError, get_package_share_directory
    except ImportError:
        for prefix in os.environ.get('AMENT_PREFIX_PATH', '').split(os.pathsep):
            marker = Path(prefix, 'share', 'ament_index', 'resource_index', 'packages', package)
            if prefix and marker.is_file():
                return Path(prefix, 'share', package)
        return None
    try:
        return Path(get_package_share_directory(package))
    except (PackageNotFoundError, ValueError, LookupError):
        return None


def config_dir() -> Path | None:
    """The top-level ``config/`` of this source checkout (editable installs), or None."""
    checkout = Path(__file__).resolve().parents[3]  # src/mindgrasp_common/mindgrasp_common/
    config = checkout / 'config'
    return config if config.is_dir() and (checkout / 'src' / 'mindgrasp_common').is_dir() else None


def _config_file(package: str, segments: list[str]) -> Path:
    """The file ``segments`` (``['param', 'fsm.yaml']``) of ``package``, a folder that lives in
    ``config/`` (:data:`CONFIG_FOLDERS`): the installed ``share/mindgrasp_bringup/config/...``,
    else the checkout's. Raises ResourceNotFoundError naming where it looked and what is there."""
    folder = CONFIG_FOLDERS[(package, segments[0])]
    rel = [folder, *segments[1:]] if folder else segments[1:]
    share = _share_dir(CONFIG_PACKAGE)
    bases = [base for base in (share / 'config' if share else None, config_dir()) if base]
    for base in bases:
        if base.joinpath(*rel).exists():
            return base.joinpath(*rel)
    where = bases[0].joinpath(*rel[:-1]) if bases else None
    known = sorted(c.name for c in where.iterdir()) if where and where.is_dir() else []
    msg = (f"The file {'/'.join(segments)!r} of {package!r} is a config file, looked for as "
           f"config/{'/'.join(rel)}: " + (f'{where} holds {known}' if where else
           f'no config/ found (a source checkout has it at its top; a colcon install at '
           f'share/{CONFIG_PACKAGE}/config/)') + '.')
    raise ResourceNotFoundError(msg)


def _package_dir(package: str) -> importlib.resources.abc.Traversable:
    try:
        found = importlib.util.find_spec(package) is not None
    except (ImportError, ValueError):
        found = False
    if not found:
        msg = (f'Cannot find the package {package!r} to read its data files; install the project '
               f'(pip install -e .) or put src/{package} on PYTHONPATH (source wt-env.sh).')
        raise ResourceNotFoundError(msg)
    return importlib.resources.files(package)


def resource_path(package: str, *parts: str) -> Path:
    """Path of the data file (or folder) ``parts`` of ``package``.

    Parameters
    ----------
    package : str
        Python / ROS package name, e.g. ``'mindgrasp_fsm'``.
    *parts : str
        Path inside the package, as one string with ``/`` or as separate parts
        (``'param/fsm.yaml'`` or ``'param', 'fsm.yaml'``); none: the package's data folder.

    Returns
    -------
    Path
        An existing file or folder.

    Raises
    ------
    ResourceNotFoundError
        The package is not importable, or it has no such data file; the message names both and
        lists what the folder holds.
    """
    rel = '/'.join(p.rstrip('/') for p in parts if p)
    segments = rel.split('/') if rel else []
    if rel.startswith('/') or any(seg in ('', '.', '..') for seg in segments):
        msg = (f'A data file of {package!r} must be a relative path inside the package without '
               f"'..', got {rel!r}; e.g. resource_path('mindgrasp_fsm', 'config/fsm.yaml').")
        raise ResourceNotFoundError(msg)
    if segments and (package, segments[0]) in CONFIG_FOLDERS:
        return _config_file(package, segments)
    share = _share_dir(package)
    if share is not None and share.joinpath(*segments).exists():
        return share.joinpath(*segments)
    root = _package_dir(package)
    node = root.joinpath(*segments)
    if not (node.is_file() or node.is_dir()):
        parent = root.joinpath(*segments[:-1])
        known = sorted(c.name for c in parent.iterdir() if not c.name.startswith(('.', '__')))\
            if parent.is_dir() else []
        where = '/'.join(segments[:-1]) or 'its top folder'
        hint = f'{where} holds {known}' if known else 'check the name'
        msg = (f'The package {package!r} has no data file {rel!r} ({hint}); package data is '
               'declared in pyproject.toml [tool.setuptools.package-data].')
        raise ResourceNotFoundError(msg)
    if isinstance(node, Path):
        return node
    return _extracted.enter_context(importlib.resources.as_file(node))


def resolve_path(value: str | Path, package: str, suffixes: tuple[str, ...] = ()) -> Path:
    """A path a user gave (parameter, argument) for a file ``package`` may also ship.

    In order:

    - ``package://<pkg>/<rel>``: the data file ``rel`` of ``pkg`` (:func:`resource_path`);
    - an absolute path, or a relative one that exists from the working directory: as given;
    - a relative path that names a data file of ``package`` (``models/default_classifier.json``);
    - else ``value`` unchanged, so the caller reports the missing file with its own advice.

    ``suffixes``: the value may name a file set by its stem (``models/shape_cnn`` for
    ``shape_cnn.json`` + ``shape_cnn.pt``); a candidate exists when one of ``stem + suffix`` does.

    Raises
    ------
    ResourceNotFoundError
        For a ``package://`` URI whose package or file does not exist.
    """
    text = str(value)
    if text.startswith(PACKAGE_URI):
        pkg, _, rel = text[len(PACKAGE_URI):].partition('/')
        if not suffixes:
            return resource_path(pkg, rel)
        folder, _, name = rel.rpartition('/')
        found = resource_path(pkg, folder) / name
        if not _exists(found, suffixes):
            msg = (f'The package {pkg!r} has no data file {rel!r} (nor {rel}{suffixes[0]}); '
                   'check the name.')
            raise ResourceNotFoundError(msg)
        return found
    path = Path(text).expanduser()
    if path.is_absolute() or _exists(path, suffixes):
        return path
    with contextlib.suppress(ResourceNotFoundError):
        found = resource_path(package, *path.parent.parts) / path.name
        if _exists(found, suffixes):
            return found
    return path


def _exists(path: Path, suffixes: tuple[str, ...]) -> bool:
    return path.exists() or any(path.with_name(path.name + s).exists() for s in suffixes)
