"""ament_python package for colcon build; the root pyproject.toml also installs it.

Metadata is in setup.cfg. The package has no data files: it installs its modules, package.xml,
the ament index marker and the ``mindgrasp`` console script (the root setup.py installs the same
script and every package's ``mindgrasp.*`` entry points for the root install).
"""

import re
from pathlib import Path

from setuptools import find_packages, setup

package_name = 'mindgrasp_cli'
package_xml = (Path(__file__).resolve().parent / 'package.xml').read_text(encoding='utf-8')

setup(
    packages=find_packages(exclude=['test']),
    data_files=[('share/ament_index/resource_index/packages', ['resource/' + package_name]),
                ('share/' + package_name, ['package.xml'])],
    # one description: package.xml's
    description=re.search(r'<description>(.*?)</description>', package_xml, re.S).group(1),
    entry_points={
        'console_scripts': [
            'mindgrasp = mindgrasp_cli.cli:main',
        ],
        # the command line's own commands and verbs (cli.py discovers them with every other
        # package's, as ros2cli does)
        'mindgrasp.command': [
            'run = mindgrasp_cli.commands.run',
        ],
        'mindgrasp.verb': [
            'topic list = mindgrasp_cli.commands.topic_list',
            'topic echo = mindgrasp_cli.commands.topic_echo',
            'topic hz = mindgrasp_cli.commands.topic_hz',
            'topic info = mindgrasp_cli.commands.topic_info',
            'topic pub = mindgrasp_cli.commands.topic_pub',
            'node list = mindgrasp_cli.commands.node_list',
            'node info = mindgrasp_cli.commands.node_info',
            'service list = mindgrasp_cli.commands.service_list',
            'service type = mindgrasp_cli.commands.service_type',
            'service call = mindgrasp_cli.commands.service_call',
            'interface list = mindgrasp_cli.commands.interface_list',
            'interface show = mindgrasp_cli.commands.interface_show',
            'interface proto = mindgrasp_cli.commands.interface_proto',
            'param list = mindgrasp_cli.commands.param_list',
            'param get = mindgrasp_cli.commands.param_get',
            'param set = mindgrasp_cli.commands.param_set',
            'param describe = mindgrasp_cli.commands.param_describe',
            'param dump = mindgrasp_cli.commands.param_dump',
            'param load = mindgrasp_cli.commands.param_load',
        ],
    },
)
