"""The README's "Adding a node": a node is its module, its entry point and a launch file, nothing
else (issue 41). The worked example's three files are taken from the README as written and run:
the module added to its package from a folder of this test (the package's ``__path__``), its
launch file started by ``mindgrasp launch --lockstep``."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def _example() -> dict[str, str]:
    """``{path: text}`` of the section's numbered code blocks (``# 1. <path>`` first lines)."""
    text = (REPO / 'README.md').read_text(encoding='utf-8')
    section = text.split('### Adding a node', 1)[1].split('\n## ', 1)[0]
    blocks = re.findall(r'```python\n# (\d)\. (\S+)[^\n]*\n(.*?)```', section, re.S)
    assert [n for n, _path, _code in blocks] == ['1', '2', '3'], 'three numbered files'
    return {path.rstrip(','): code for _n, path, code in blocks}


def test_the_example_touches_three_files_a_module_an_entry_point_and_a_launch_file() -> None:
    files = list(_example())
    assert files[0].endswith('_node.py') and files[1].endswith('setup.py')
    assert files[2].startswith('src/mindgrasp_bringup/mindgrasp_bringup/launch/')
    assert files[2].endswith('.launch.py')
    assert not any((REPO / f).is_file() for f in (files[0], files[2])), 'an example, not a node'


def test_the_example_node_runs_from_its_three_files(tmp_path: Path) -> None:
    module_path, setup_path, launch_path = _example()
    code = _example()
    package, module = Path(module_path).parts[-2], Path(module_path).stem
    # 1. the module, in a folder added to its package's __path__
    extra = tmp_path / 'extra' / package
    extra.mkdir(parents=True)
    (extra / f'{module}.py').write_text(code[module_path], encoding='utf-8')
    # 2. the entry point names the module's main (what setup.py gets; the launcher and
    # `ros2 run` find the node by it: <package>.<executable>)
    entry = re.fullmatch(r"'(\w+) = ([\w.]+):main',\n", code[setup_path])
    assert entry, code[setup_path]
    executable, target = entry.groups()
    assert target == f'{package}.{module}' and executable == module
    # 3. the launch file, run on simulated time
    launch_file = tmp_path / Path(launch_path).name
    launch_file.write_text(code[launch_path], encoding='utf-8')
    assert f"executable='{executable}'" in code[launch_path]
    script = (f'import sys, {package}; {package}.__path__.append({str(extra)!r}); '
              'from mindgrasp_cli.cli import main; sys.exit(main(sys.argv[1:]))')
    run = subprocess.run([sys.executable, '-c', script, 'launch', str(launch_file), '--lockstep',
                          '--duration', '3', '--run-dir', str(tmp_path / 'run')],
                         capture_output=True, text=True, timeout=300, check=False)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-3000:]
    logged = sorted(set(re.findall(r'ROS time (\d+\.\d+) s', out)), key=float)
    assert logged[:3] == ['0.500', '1.000', '1.500'], out[-3000:]
