"""ament_python package for colcon build; the root pyproject.toml also installs it."""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_bringup'
here = Path(__file__).resolve().parent
# one description: package.xml's
DESCRIPTION = re.search(r'<description>(.*?)</description>',
                        (here / 'package.xml').read_text(encoding='utf-8'), re.S).group(1)


def share_files() -> list[tuple[str, list[str]]]:
    """Data files of the Python package (parameter YAML, scenes, URDF, models, launch files) also
    installed to share/<package>/<same path>, where ament_index and ``ros2 launch`` find them."""
    groups: dict[str, list[str]] = {}
    for path in sorted((here / package_name).rglob('*')):
        rel = path.relative_to(here / package_name)
        if (not path.is_file() or '__pycache__' in rel.parts or rel.parts[0].startswith('.')
                or (path.suffix == '.py' and not path.name.endswith('.launch.py'))
                or len(rel.parts) == 1):
            continue
        groups.setdefault(str(Path('share', package_name, rel.parent)), []).append(
            str(path.relative_to(here)))
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
            'mindgrasp = mindgrasp_bringup.cli:main',
        ],
        # the mindgrasp command's own commands and verbs (cli.py discovers them, as ros2cli does)
        'mindgrasp.command': [
            'launch = mindgrasp_bringup.commands.launch',
            'run = mindgrasp_bringup.commands.run',
            'replay = mindgrasp_bringup.commands.replay',
        ],
        'mindgrasp.verb': [
            'topic list = mindgrasp_bringup.commands.topic_list',
            'topic echo = mindgrasp_bringup.commands.topic_echo',
            'topic hz = mindgrasp_bringup.commands.topic_hz',
            'topic info = mindgrasp_bringup.commands.topic_info',
            'topic pub = mindgrasp_bringup.commands.topic_pub',
            'node list = mindgrasp_bringup.commands.node_list',
            'node info = mindgrasp_bringup.commands.node_info',
            'service list = mindgrasp_bringup.commands.service_list',
            'service type = mindgrasp_bringup.commands.service_type',
            'service call = mindgrasp_bringup.commands.service_call',
            'interface list = mindgrasp_bringup.commands.interface_list',
            'interface show = mindgrasp_bringup.commands.interface_show',
            'interface proto = mindgrasp_bringup.commands.interface_proto',
            'param list = mindgrasp_bringup.commands.param_list',
            'param get = mindgrasp_bringup.commands.param_get',
            'param set = mindgrasp_bringup.commands.param_set',
            'param describe = mindgrasp_bringup.commands.param_describe',
            'param dump = mindgrasp_bringup.commands.param_dump',
            'param load = mindgrasp_bringup.commands.param_load',
            'session run = mindgrasp_bringup.session_cli',
            'session resume = mindgrasp_bringup.session_cli',
            'session calibrate = mindgrasp_bringup.session_cli',
        ],
    },
)
