"""Run directories: ``runs/<UTC timestamp>_<profile>/`` with everything needed to redo a run.

Layout::

    launch.yaml             profile, launch file, command line, processes and their commands
    launch_arguments.yaml   every launch argument with its value (given or default)
    params.yaml             resolved parameters of every node (ROS YAML, by node name)
    params/<node>.yaml      the file each node got with --params-file
    params/changes.jsonl    live parameter changes while the run went on (the recorder)
    provenance.yaml         git revision, package versions, Python, host, ROS environment
    logs/<node>.log         output of each process; logs/launch.log: the launcher's messages
    bag/                    the rosbag2 recording (record:=true)
    summary.yaml            how the launch and each process ended (written at the end)
    report.md               timing of the run from its bag (written at the end; latency.json)
"""

from __future__ import annotations

import datetime as dt
import importlib.metadata
import os
import platform
import re
import socket
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from mindgrasp_common.resources import resource_path
from mindgrasp_common.safe_files import write_atomic
from mindgrasp_launch.errors import LaunchError

DIST_NAME = 'mindgrasp-ros'
_ENV_KEYS = ('ROS_DOMAIN_ID', 'ROS_AUTOMATIC_DISCOVERY_RANGE', 'ROS_STATIC_PEERS',
             'RMW_IMPLEMENTATION', 'MINDGRASP_RMW', 'CYCLONEDDS_URI', 'ROS_DISTRO')


def utc_stamp(now: dt.datetime | None = None) -> str:
    """``20261121T005316Z`` (UTC, sorts by time)."""
    now = now or dt.datetime.now(dt.timezone.utc)
    return now.strftime('%Y%m%dT%H%M%SZ')


def default_runs_root() -> Path:
    """``$MINDGRASP_RUNS_DIR`` or ``./runs``."""
    return Path(os.environ.get('MINDGRASP_RUNS_DIR', 'runs'))


def create_run_dir(profile: str, run_dir: str | Path | None = None,
                   runs_root: str | Path | None = None, option: str = '--run-dir') -> Path:
    """Create the run directory; an explicit ``run_dir`` must not hold files already, and only
    the run directory itself is created: its parent folder must exist (``--out /nonexistent/x``
    created /nonexistent at the filesystem root). ``option`` names the command's option in the
    errors (``--run-dir``, ``--out``)."""
    if run_dir is not None:
        path = Path(run_dir).expanduser()
        if path.exists() and (not path.is_dir() or any(path.iterdir())):
            msg = (f'{option} {path} exists and is not empty: choose a new {option} or '
                   f'remove it (a run never overwrites recorded data).')
            raise LaunchError(msg)
        parent = path.absolute().parent
        if not parent.is_dir():
            msg = (f'{option} {path}: the folder {parent} does not exist; give a run directory '
                   f'in an existing folder (only the run directory itself is created).')
            raise LaunchError(msg)
        try:
            path.mkdir(exist_ok=True)
        except OSError as exc:
            msg = (f'cannot create the run directory {path} ({exc.strerror or exc}): give a '
                   f'writable {option}.')
            raise LaunchError(msg) from None
    else:
        root = Path(runs_root) if runs_root is not None else default_runs_root()
        safe = re.sub(r'[^A-Za-z0-9_.-]+', '_', profile) or 'launch'
        base = root / f'{utc_stamp()}_{safe}'
        path, n = base, 1
        # mkdir claims the name atomically: two launches in the same second (another shell, a
        # parallel test) get -2, -3 ... instead of sharing one directory
        while True:
            try:
                root.mkdir(parents=True, exist_ok=True)
                path.mkdir()
                break
            except FileExistsError:
                n += 1
                path = base.with_name(f'{base.name}-{n}')
            except OSError as exc:
                msg = (f'cannot create the run directory {path} ({exc.strerror or exc}): give a '
                       f'writable {option}.')
                raise LaunchError(msg) from None
    try:
        (path / 'logs').mkdir(exist_ok=True)
    except OSError as exc:
        msg = (f'cannot create the run directory {path} ({exc.strerror or exc}): give a '
               f'writable {option}.')
        raise LaunchError(msg) from None
    return path.resolve()


def _source_dir() -> Path:
    """Where the running code lives (git finds the checkout enclosing it, if any)."""
    return resource_path('mindgrasp_launch')


def _git(*args: str) -> str | None:
    try:
        out = subprocess.run(['git', '-C', str(_source_dir()), *args], capture_output=True,
                             text=True, timeout=10, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() if out.returncode == 0 else None


def git_info() -> dict[str, Any]:
    """Revision, branch and whether the working tree has uncommitted changes."""
    revision = _git('rev-parse', 'HEAD')
    if revision is None:
        return {'revision': None, 'note': f'{_source_dir()} is not in a git checkout'}
    status = _git('status', '--porcelain', '--untracked-files=no')
    return {'revision': revision, 'branch': _git('rev-parse', '--abbrev-ref', 'HEAD'),
            'dirty': bool(status), 'describe': _git('describe', '--always', '--dirty')}


def package_versions() -> dict[str, str | None]:
    """Versions of this project and of every dependency it declares (no heavy imports)."""
    def version(name: str) -> str | None:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return None

    out = {DIST_NAME: version(DIST_NAME)}
    try:
        requires = importlib.metadata.requires(DIST_NAME) or []
    except importlib.metadata.PackageNotFoundError:
        requires = []
    for req in requires:
        if 'extra ==' in req:
            continue
        name = re.split(r'[\s<>=!~;\[]', req, maxsplit=1)[0]
        out[name] = version(name)
    return out


def provenance() -> dict[str, Any]:
    """What produced a run: code revision, package versions, Python, host, ROS environment."""
    return {
        'git': git_info(),
        'packages': package_versions(),
        'python': sys.version.split()[0],
        'executable': sys.executable,
        'platform': platform.platform(),
        'hostname': socket.gethostname(),
        'ros_environment': {k: os.environ[k] for k in _ENV_KEYS if k in os.environ},
    }


def write_yaml(path: Path, data: Mapping[str, Any] | str, header: str = '') -> None:
    """Write YAML (a mapping or ready text) with an optional ``#`` comment header.

    Atomic (temporary file + rename): a full disk leaves the previous version, never a
    truncated file.

    Raises:
        OSError: the file could not be written.
    """
    text = data if isinstance(data, str) else yaml.safe_dump(dict(data), sort_keys=False,
                                                             width=100)
    if header:
        text = ''.join(f'# {line}\n' for line in header.splitlines()) + text
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, lambda tmp: tmp.write_text(text, encoding='utf-8'))
