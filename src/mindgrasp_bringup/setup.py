"""ament_python package for colcon build; the root pyproject.toml also installs it."""

import os
import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_bringup'
here = Path(__file__).resolve().parent
# one description: package.xml's
DESCRIPTION = re.search(r'<description>(.*?)</description>',
                        (here / 'package.xml').read_text(encoding='utf-8'), re.S).group(1)


def share_files(root: Path = here / package_name, share: Path = Path('share', package_name),
                subfolders_only: bool = True) -> list[tuple[str, list[str]]]:
    """Data files of the Python package (launch files, the Foxglove layouts) also installed to
    share/<package>/<same path>, where ament_index and ``ros2 launch`` find them; with ``root``
    the repository's top-level config/ (parameter files, profiles, scenes, plans: what a user
    edits) to share/<package>/config/, where ``mindgrasp_common.resources`` looks for it."""
    groups: dict[str, list[str]] = {}
    for path in sorted(root.rglob('*')):
        rel = path.relative_to(root)
        if (not path.is_file() or '__pycache__' in rel.parts or rel.parts[0].startswith('.')
                or (path.suffix == '.py' and not path.name.endswith('.launch.py'))
                or (subfolders_only and len(rel.parts) == 1)):
            continue
        # relative to this folder (colcon requires it), config/ by '../../config/...'
        groups.setdefault(str(share / rel.parent), []).append(os.path.relpath(path, here))
    return sorted(groups.items())


setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    # data files inside the Python package, as the root pyproject.toml ships them
    package_data={'': [f'**/*.{ext}' for ext in ('yaml', 'json', 'urdf', 'xml', 'txt', 'msg', 'srv',
                                                 'npz', 'pt', 'stl', 'obj', 'launch.py')]},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        *share_files(),
        *share_files(here.parents[1] / 'config', Path('share', package_name, 'config'), False),
    ],
    install_requires=['setuptools'],
    zip_safe=False,
    maintainer='MIndGrasp-ROS maintainers',
    maintainer_email='maintainers@users.noreply.github.com',
    description=DESCRIPTION,
    license='MIT',
    entry_points={
        'console_scripts': [
            'foxglove_bridge_node = mindgrasp_bringup.foxglove_bridge_node:main',
            'replay_node = mindgrasp_bringup.replay.replay_node:main',
        ],
        # this package's command and verbs of the mindgrasp command (mindgrasp_cli discovers
        # them, as ros2cli does)
        'mindgrasp.command': [
            'replay = mindgrasp_bringup.commands.replay',
        ],
        'mindgrasp.verb': [
            'session run = mindgrasp_bringup.commands.session',
            'session resume = mindgrasp_bringup.commands.session',
            'session calibrate = mindgrasp_bringup.commands.session',
        ],
    },
)
