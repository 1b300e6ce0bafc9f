"""src/ as a ROS 2 workspace: package.xml files valid for catkin_pkg, ament_python packages with
console scripts for their nodes, and a real ``colcon build`` whose installed executables run.

``colcon build`` runs with colcon-core + colcon-ros from PyPI (test extra), over every package but
``mindgrasp_msgs`` (an ament_cmake interface package: it needs rosidl, i.e. ROS 2 installed).
"""

from __future__ import annotations

import ast
import configparser
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from catkin_pkg.package import parse_package

from mindgrasp_launch.actions.node import node_module
from mindgrasp_testing import console_scripts, spin_until

REPO = Path(__file__).resolve().parents[2]
SRC = REPO / 'src'
PACKAGES = sorted(p for p in SRC.iterdir() if (p / 'package.xml').is_file())
PYTHON_PACKAGES = [p for p in PACKAGES if p.name != 'mindgrasp_msgs']
#: a package using another: importing it, or running it (``'-m', 'mindgrasp_x'``)
USES = re.compile(r"^\s*(?:from|import) (mindgrasp_(?!msgs)\w+)|'-m', '(mindgrasp_\w+)", re.M)


def _declared(package_dir: Path) -> set[str]:
    package = parse_package(package_dir / 'package.xml')
    return {d.name for d in package.exec_depends + package.build_depends}


def _used(package_dir: Path) -> set[str]:
    """Our packages that the Python code of ``package_dir`` imports or runs (-m), lazy
    imports inside functions included."""
    text = ''.join(p.read_text(encoding='utf-8')
                   for p in (package_dir / package_dir.name).rglob('*.py'))
    return {a or b for a, b in USES.findall(text)} - {package_dir.name}


def test_every_package_folder_is_a_ros_package() -> None:
    folders = sorted(p.name for p in SRC.iterdir() if p.name.startswith('mindgrasp_'))
    assert folders == [p.name for p in PACKAGES], 'every src/mindgrasp_<x>/ needs a package.xml'
    assert 'mindgrasp_msgs' in folders


@pytest.mark.parametrize('package_dir', PACKAGES, ids=lambda p: p.name)
def test_package_xml_is_valid_format_3(package_dir: Path) -> None:
    package = parse_package(package_dir / 'package.xml')  # parses and validates (raises)
    package.validate()
    assert package.package_format == 3
    assert package.name == package_dir.name
    build_type = package.get_build_type()
    assert build_type == ('ament_cmake' if package.name == 'mindgrasp_msgs' else 'ament_python')
    # our own packages it uses are declared (colcon orders the build by them)
    used = _used(package_dir) if build_type == 'ament_python' else set()
    declared = _declared(package_dir)
    assert used <= declared, f'{package.name}: declare {sorted(used - declared)}'


#: rosdep keys of Python libraries -> the module the code imports
ROSDEP_MODULES = {
    'python3-numpy': 'numpy', 'python3-scipy': 'scipy', 'python3-yaml': 'yaml',
    'python3-tqdm': 'tqdm', 'python3-matplotlib': 'matplotlib', 'python3-sklearn': 'sklearn',
    'python3-psutil': 'psutil', 'python3-rosbags-pip': 'rosbags', 'python3-pyarrow-pip': 'pyarrow',
    'python3-pybullet-pip': 'pybullet', 'python3-opencv': 'cv2', 'python3-pygame': 'pygame',
    'python3-torch': 'torch', 'rclpy': 'rclpy', 'launch': 'launch', 'launch_ros': 'launch_ros'}
#: declared without an import, each with why
DECLARED_UNUSED = {
    ('mindgrasp_bringup', 'mindgrasp_cli'): 'its verbs (replay, session) are commands of the '
                                            'mindgrasp command line',
}


def _imports(package_dir: Path) -> set[str]:
    """Every module name the package's code imports (at any depth, lazy ones included)."""
    found = set()
    for path in (package_dir / package_dir.name).rglob('*.py'):
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                found.add(node.module)
    return found


def _needed(package_dir: Path) -> set[str]:
    """What the package's code needs at run time: our packages it imports or runs (-m), the
    ones its launch files start, ``mindgrasp_msgs`` when it uses its messages, and the
    libraries of :data:`ROSDEP_MODULES` it imports."""
    imports = _imports(package_dir)
    tops = {m.split('.')[0] for m in imports}
    needed = _used(package_dir) | {t for t in tops if t.startswith('mindgrasp_')}
    code = ''.join(p.read_text(encoding='utf-8')
                   for p in (package_dir / package_dir.name).rglob('*.py'))
    if any('.mindgrasp_msgs' in m for m in imports) or "'mindgrasp_msgs/" in code:
        needed.add('mindgrasp_msgs')     # its messages, or their type names (get_message_class)
    for launch_file in (package_dir / package_dir.name).rglob('*.launch.py'):
        needed |= set(re.findall(r"package='(mindgrasp_\w+)'", launch_file.read_text()))
        needed |= {'launch', 'launch_ros'}      # run by ros2 launch
    needed |= {key for key, module in ROSDEP_MODULES.items() if module in tops}
    return needed - {package_dir.name}


@pytest.mark.parametrize('package_dir', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_package_xml_declares_what_the_code_needs_and_no_more(package_dir: Path) -> None:
    """Our packages and the Python libraries of :data:`ROSDEP_MODULES` (message packages and
    pip-only libraries without a rosdep key are not compared): declared exactly when needed
    (a launch file may start a package that may not be declared: one that depends on this one,
    as mindgrasp_experiments' nodes in mindgrasp_bringup's launch files)."""
    name = package_dir.name
    declared = {d for d in _declared(package_dir)
                if d.startswith('mindgrasp_') or d in ROSDEP_MODULES}
    needed = _needed(package_dir)
    imported = {d for d in needed if d in ROSDEP_MODULES} | (_used(package_dir) & {
        p.name for p in PACKAGES})
    if any('.mindgrasp_msgs' in m for m in _imports(package_dir)):
        imported.add('mindgrasp_msgs')
    unused = {d for d in declared - needed if (name, d) not in DECLARED_UNUSED}
    undeclared = {d for d in imported - declared if d.startswith(('mindgrasp_', 'python3-'))
                  or d == 'rclpy'}
    assert not unused and not undeclared, (f'{name}/package.xml: declares {sorted(unused)} '
                                           f'that nothing needs; misses {sorted(undeclared)}')


def test_no_package_uses_a_package_that_depends_on_it() -> None:
    """The packages' dependencies (declared, and used by their code) form no cycle: colcon
    refuses a declared one, and an undeclared one breaks a workspace built package by package."""
    deps = {p.name: (_declared(p) | (_used(p) if p in PYTHON_PACKAGES else set()))
            & {q.name for q in PACKAGES} for p in PACKAGES}

    def reaches(start: str, goal: str, seen: set[str]) -> bool:
        return any(d == goal or (d not in seen and reaches(d, goal, seen | {d}))
                   for d in deps[start])

    cycles = sorted(f'{a} -> {b} -> ... -> {a}' for a in deps for b in deps[a]
                    if reaches(b, a, {b}))
    assert not cycles, '\n'.join(cycles)


#: the layering of the packages that start and inspect a graph, as ROS's launch, ros2cli and a
#: bringup package: the launcher uses neither the command line nor the launch files' package; the
#: command line uses the launcher (``run``, ``--version``) but no launch file; bringup (launch
#: files, replay, sessions) sits on both
LAYERS = {'mindgrasp_launch': {'mindgrasp_cli', 'mindgrasp_bringup', 'mindgrasp_experiments'},
          'mindgrasp_cli': {'mindgrasp_bringup', 'mindgrasp_experiments'},
          'mindgrasp_bag': {'mindgrasp_launch', 'mindgrasp_cli', 'mindgrasp_bringup'}}


@pytest.mark.parametrize('package', sorted(LAYERS))
def test_launch_and_cli_use_no_package_above_them(package: str) -> None:
    package_dir = SRC / package
    above = (_used(package_dir) | _declared(package_dir)) & LAYERS[package]
    assert not above, f'{package} uses {sorted(above)}, which sit above it'


def test_bringup_sits_on_the_launcher_and_the_command_line() -> None:
    declared = _declared(SRC / 'mindgrasp_bringup')
    assert {'mindgrasp_launch', 'mindgrasp_cli', 'mindgrasp_bag'} <= declared


def test_readme_layout_shows_every_package() -> None:
    """The root README's layout block names each package folder (and config/), and each package
    has a README of its own."""
    readme = (REPO / 'README.md').read_text(encoding='utf-8')
    block = readme.split('## Layout', 1)[1].split('```')[1]
    listed = re.findall(r'^(\S+)/\s', block, re.M)
    packages = {f'src/{p.name}' for p in PACKAGES}
    assert {name for name in listed if name.startswith('src/')} == packages, listed
    assert 'config' in listed
    assert [p.name for p in PACKAGES if not (p / 'README.md').is_file()] == []


@pytest.mark.parametrize('package_dir', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_ament_python_layout(package_dir: Path) -> None:
    name = package_dir.name
    assert (package_dir / 'resource' / name).is_file()
    assert (package_dir / name / '__init__.py').is_file()
    config = configparser.ConfigParser()
    config.read(package_dir / 'setup.cfg')
    # console scripts go to lib/<package>/, where `ros2 run <package> <executable>` looks
    assert config['develop']['script_dir'] == f'$base/lib/{name}'
    assert config['install']['install_scripts'] == f'$base/lib/{name}'


def _data_files_wanted(package_dir: Path) -> set[tuple[str, str]]:
    """(share folder, file relative to the package folder) of every data file: the files in
    the Python package's subfolders but modules (launch files are data), and for the bringup
    package the whole top-level config/ under share/<package>/config/."""
    name = package_dir.name
    roots = [(package_dir / name, Path('share', name), True)]
    if name == 'mindgrasp_bringup':
        roots.append((REPO / 'config', Path('share', name, 'config'), False))
    wanted = {('share/ament_index/resource_index/packages', f'resource/{name}'),
              (f'share/{name}', 'package.xml')}
    for root, share, subfolders_only in roots:
        for path in root.rglob('*'):
            rel = path.relative_to(root)
            if (path.is_file() and '__pycache__' not in rel.parts
                    and not rel.parts[0].startswith('.')
                    and (path.suffix != '.py' or path.name.endswith('.launch.py'))
                    and not (subfolders_only and len(rel.parts) == 1)):
                wanted.add(((share / rel.parent).as_posix(),
                            os.path.relpath(path, package_dir).replace(os.sep, '/')))
    return wanted


@pytest.mark.parametrize('package_dir', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_setup_cfg_installs_every_data_file(package_dir: Path) -> None:
    """One declarative list per package (setup.cfg ``[options.data_files]``, globs): setuptools
    reads it in a standalone build of the package, so no setup.py carries a copy of a helper.
    A new data folder (a new config/ subfolder) needs its line there: this test names it."""
    from setuptools.config.setupcfg import read_configuration

    declared = read_configuration(package_dir / 'setup.cfg')['options']['data_files']
    installed = {(dest, src) for dest, sources in declared for src in sources}
    wanted = _data_files_wanted(package_dir)
    assert installed == wanted, (f'missing from setup.cfg: {sorted(wanted - installed)}; '
                                 f'not data: {sorted(installed - wanted)}')
    assert 'data_files=' not in (package_dir / 'setup.py').read_text(encoding='utf-8')


@pytest.mark.parametrize('package_dir', PYTHON_PACKAGES, ids=lambda p: p.name)
def test_every_node_has_a_console_script_our_launcher_resolves(package_dir: Path) -> None:
    name = package_dir.name
    scripts = console_scripts(package_dir)
    nodes = {p.stem for p in (package_dir / name).rglob('*_node.py')
             if re.search(r'^def main\(', p.read_text(encoding='utf-8'), re.M)}
    assert nodes <= set(scripts), f'{name}: add console scripts for {sorted(nodes - set(scripts))}'
    for executable, target in scripts.items():
        module, _, function = target.partition(':')
        assert function == 'main'
        assert (package_dir / Path(*module.split('.'))).with_suffix('.py').is_file(), target
        if executable.endswith('_node'):
            # Node(package=, executable=) runs the same code under mindgrasp launch and ros2 launch
            assert node_module(name, executable) == module


def test_launch_files_name_installed_executables() -> None:
    scripts = {p.name: console_scripts(p) for p in PYTHON_PACKAGES}
    bringup = SRC / 'mindgrasp_bringup' / 'mindgrasp_bringup'
    files = [*sorted((bringup / 'launch').glob('*.launch.py')),
             SRC / 'mindgrasp_launch' / 'mindgrasp_launch' / 'common.py']
    pairs = set()
    for path in files:
        text = path.read_text(encoding='utf-8')
        pairs |= set(re.findall(r"package='(\w+)',\s*executable='(\w+)'", text))
        # a package name, not a subpackage's module path (package='mindgrasp_bringup.replay')
        assert not re.search(r"package='mindgrasp_\w+\.", text)
    assert len(pairs) >= 8
    for package, executable in sorted(pairs):
        assert executable in scripts[package], f'{package} has no console script {executable}'


# -- a real colcon build ----------------------------------------------------------------------


@pytest.fixture(scope='module')
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``colcon build`` of the Python packages into a temporary workspace (install/, build/)."""
    colcon = shutil.which('colcon') or str(Path(sys.executable).with_name('colcon'))
    if not Path(colcon).is_file():
        pytest.fail('colcon is not installed: pip install -c constraints.txt -e ".[test]"')
    ws = tmp_path_factory.mktemp('colcon_ws')
    result = subprocess.run(
        [colcon, '--log-base', str(ws / 'log'), 'build',
         '--base-paths', *(str(p) for p in PYTHON_PACKAGES),
         '--build-base', str(ws / 'build'), '--install-base', str(ws / 'install'),
         '--event-handlers', 'console_direct-'],
        cwd=ws, capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    return ws


def sourced(ws: Path, *command: str) -> list[str]:
    """``command`` run after sourcing the workspace's setup.sh, as a ROS user does."""
    return ['bash', '-c', '. "$0/install/setup.sh" && exec "$@"', str(ws), *command]


def workspace_env() -> dict[str, str]:
    """The test's environment without the source tree on PYTHONPATH: the workspace's setup.sh
    provides the installed packages (mindgrasp_ros carries a copy of the mindgrasp_msgs interface
    files, so the runtime needs no built mindgrasp_msgs)."""
    env = {k: v for k, v in os.environ.items()
           if k not in ('PYTHONPATH', 'AMENT_PREFIX_PATH', 'MINDGRASP_MSGS_DIR')}
    env['PATH'] = os.pathsep.join([str(Path(sys.executable).parent), env.get('PATH', '')])
    return env


@pytest.mark.slow
def test_colcon_installs_executables_and_share_files(workspace: Path) -> None:
    install = workspace / 'install'
    for package_dir in PYTHON_PACKAGES:
        name = package_dir.name
        share = install / name / 'share'
        assert (share / 'ament_index' / 'resource_index' / 'packages' / name).is_file()
        assert (share / name / 'package.xml').is_file()
        for executable in console_scripts(package_dir):
            assert os.access(install / name / 'lib' / name / executable, os.X_OK), executable
    launch = install / 'mindgrasp_bringup' / 'share' / 'mindgrasp_bringup' / 'launch'
    assert (launch / 'demo.launch.py').is_file()  # ros2 launch mindgrasp_bringup demo.launch.py
    # the top-level config/ (what a user edits) is the bringup package's share files, where the
    # installed code finds it: no source tree, no ROS 2, only the sourced workspace
    config = install / 'mindgrasp_bringup' / 'share' / 'mindgrasp_bringup' / 'config'
    assert sorted(p.relative_to(config).as_posix() for p in config.rglob('*.yaml')) == sorted(
        p.relative_to(REPO / 'config').as_posix() for p in (REPO / 'config').rglob('*.yaml'))
    found = subprocess.run(
        sourced(workspace, sys.executable, '-c',
                'from mindgrasp_common.resources import resource_path as r; '
                'print(r("mindgrasp_fsm", "param/fsm.yaml")); print(r("mindgrasp_sim", "scenes")); '
                'print(r("mindgrasp_bringup", "param/demo.yaml")); '
                'print(r("mindgrasp_sim", "robots/xarm6.yaml")); '
                'print(r("mindgrasp_sim", "urdf/mindgrasp_arm.urdf"))'),
        env=workspace_env(), capture_output=True, text=True, timeout=120, check=False)
    assert found.returncode == 0, found.stderr
    assert found.stdout.split() == [str(config / 'param' / 'fsm.yaml'), str(config / 'scenes'),
                                    str(config / 'profiles' / 'demo.yaml'),
                                    str(config / 'robots' / 'xarm6.yaml'),
                                    str(config / 'robots' / 'urdf' / 'mindgrasp_arm.urdf')]
    cli = install / 'mindgrasp_cli' / 'lib' / 'mindgrasp_cli' / 'mindgrasp'
    help_run = subprocess.run(sourced(workspace, str(cli), '--help'), env=workspace_env(),
                              capture_output=True, text=True, timeout=120, check=False)
    assert help_run.returncode == 0, help_run.stderr
    assert 'launch' in help_run.stdout
    # each installed package brings its own commands and verbs (entry points in its setup.py)
    registered = subprocess.run(
        sourced(workspace, sys.executable, '-c',
                'import importlib.metadata as m; print(sorted({(e.name, e.dist.name) for g in '
                '("mindgrasp.verb", "mindgrasp.command") for e in m.entry_points(group=g)}))'),
        env=workspace_env(), capture_output=True, text=True, timeout=120, check=True).stdout
    for verb, package in [('bag record', 'mindgrasp_bag'), ('topic echo', 'mindgrasp_cli'),
                          ('session run', 'mindgrasp_bringup'),
                          ('train classifier', 'mindgrasp_classifier'),
                          ('train vision', 'mindgrasp_vision'),
                          ('eeg fit-virtual', 'mindgrasp_experiments'),
                          ('launch', 'mindgrasp_launch'), ('run', 'mindgrasp_cli'),
                          ('replay', 'mindgrasp_bringup')]:
        assert repr((verb, package)) in registered, registered
    # an installed node executable (ros2 run mindgrasp_fsm fsm_node --help): its docstring and
    # the ROS arguments, without starting the node
    node_help = subprocess.run(
        sourced(workspace, str(install / 'mindgrasp_fsm' / 'lib' / 'mindgrasp_fsm' / 'fsm_node'),
                '--help'), env=workspace_env(), capture_output=True, text=True, timeout=120,
        check=False)
    assert node_help.returncode == 0, node_help.stderr
    assert 'six-state MIndGrasp controller' in node_help.stdout
    assert '--ros-args' in node_help.stdout and 'param describe' in node_help.stdout
    assert 'Grasp controller ready' not in node_help.stdout + node_help.stderr
    # the sourced workspace's copies are imported, not the source tree or an editable install
    where = subprocess.run(
        sourced(workspace, sys.executable, '-c',
                'import mindgrasp_trainer, mindgrasp_ros; '
                'print(mindgrasp_trainer.__file__); print(mindgrasp_ros.__file__)'),
        env=workspace_env(), capture_output=True, text=True, timeout=120, check=True)
    assert all(line.startswith(str(install)) for line in where.stdout.split()), where.stdout


@pytest.mark.slow
def test_installed_node_runs_against_our_runtime(workspace: Path, rclpy_ctx, tmp_path) -> None:
    """``ros2 run mindgrasp_trainer graz_node`` (the installed console script, the installed
    packages): its cues arrive over DDS in this process, and it ends by itself."""
    from mindgrasp_ros.interfaces.mindgrasp_msgs.msg import Prompt

    from mindgrasp_trainer.ros_common import prompt_qos

    executable = workspace / 'install' / 'mindgrasp_trainer' / 'lib' / 'mindgrasp_trainer'
    executable /= 'graz_node'
    log = (tmp_path / 'graz.log').open('wb')
    proc = subprocess.Popen(
        sourced(workspace, str(executable), '--ros-args', '-p', 'n_trials:=2', '-p', 'seed:=3',
                '-p', 'start_delay:=1.0', '-p', 'fixation:=0.2', '-p', 'cue:=0.2',
                '-p', 'imagery:=0.3', '-p', 'rest_min:=0.1', '-p', 'rest_max:=0.2',
                '-p', 'display_rate:=0.0'),
        env=workspace_env(), stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        node = rclpy_ctx.create_node('colcon_probe')
        cues: list[object] = []
        node.create_subscription(Prompt, '/trainer/prompt', cues.append, prompt_qos())
        assert spin_until(node, lambda: len(cues) > 0, 60.0), (tmp_path / 'graz.log').read_text()
        assert proc.wait(60) == 0, (tmp_path / 'graz.log').read_text()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        log.close()
