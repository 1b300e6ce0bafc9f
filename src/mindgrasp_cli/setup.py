"""ament_python package for colcon build; the root pyproject.toml also installs it.

Metadata and the data files (package.xml, the ament index marker) are in setup.cfg, the
description copied from package.xml; here only what the root setup.py reads too, the entry
points: the ``mindgrasp`` console script (installed to lib/mindgrasp_cli/ by colcon, to the
virtualenv's bin/ by the root install) and the command line's own commands and verbs.
"""

from setuptools import find_packages, setup

setup(
    packages=find_packages(exclude=['test']),
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
